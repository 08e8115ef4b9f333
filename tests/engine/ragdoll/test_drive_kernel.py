"""The compiled drive and twist kernels (:mod:`engine.ragdoll._drive_kernel`) give, bit for bit, what
the numpy path of :mod:`engine.ragdoll._control` gives: the same MuJoCo inputs, the same steps."""

from __future__ import annotations

import copy
from typing import Any, cast

import numpy as np
import pytest

from engine import jit, quat
from engine.ragdoll import default_profile
from engine.ragdoll._control import project_twist, read_poses
from engine.ragdoll.physics import PhysicsWorld
from engine.skeleton import Skeleton

pytestmark = pytest.mark.skipif(not jit.AVAILABLE, reason="numba is not installed")

N = 4


def _world(skeleton: Skeleton) -> PhysicsWorld:
    pw = PhysicsWorld()
    pw.simulate_animated = True  # the animated ones in the model too: their placements are the kernel's
    for k in range(N):
        pw.add_ragdoll(
            k + 1, skeleton, default_profile(skeleton), [1.5 * k, 1.0, 0.0], quat.identity(skeleton.num_joints)
        )
    return pw


def _run(skeleton: Skeleton, compiled: bool, steps: int = 10) -> list[bytes]:
    """Every ragdoll driven to noisy targets (animated ones, weak and strong muscles, pins, support, a
    teleport that leaves no last target); the state after each step."""
    rng = np.random.default_rng(7)
    out = []
    with jit.use(compiled):
        pw = _world(skeleton)
        pose = quat.identity(N, skeleton.num_joints) + rng.normal(0, 0.3, (N, skeleton.num_joints, 4))
        for s in range(steps):
            for k in range(N):
                rot = pose[k] + rng.normal(0, 0.05, (skeleton.num_joints, 4))
                root = [1.5 * k, 1.0 + 0.01 * s, 0.005 * s]
                w = rng.uniform(0, 1, 3)
                pw.drive(k + 1, root, rot, w[0] if k else 0.0, w[1], w[2], kinematic=(k + s) % 3 == 0)
            if s == 4:
                pw.set_pose(2, [1.5, 1.05, 0.0], quat.identity(skeleton.num_joints))
            pw.step()
            out.append(pw.state_bytes())
    return out


def test_drive_kernel_steps_as_the_numpy_path(skeleton: Skeleton) -> None:
    """Broken in the kernel by a hinge target off by one part in ten million (``hinge + w_h * lead *
    1.0000001``), by a kinematic root velocity written before its division by ``dt``, or by the hemisphere
    flip left out of ``_qlog``: a step's state then differs."""
    assert _run(skeleton, True) == _run(skeleton, False)


def test_twist_kernel_clamps_as_the_numpy_path(skeleton: Skeleton) -> None:
    """Ball joints twisted far past their limits, with random velocities: both paths clamp the same
    joints to the same bits and remove the same outward twist velocities.

    Broken in the kernel by clamping without the swing (``qmul(swing, clamped)`` replaced by ``clamped``)
    or by removing every twist velocity (the sign test dropped): the arrays then differ."""
    pw = _world(skeleton)
    pw.step()
    L, m, d = pw.layout, pw.model, pw.data
    assert L is not None and m is not None and d is not None
    rng = np.random.default_rng(3)
    qi = L.ball_q[:, None] + np.arange(4)
    d.qpos[qi] = quat.normalize(rng.normal(0, 1, (len(L.ball_q), 4)))
    d.qvel[L.ball_d[:, None] + np.arange(3)] = rng.normal(0, 3, (len(L.ball_d), 3))
    runs = []
    for compiled in (False, True):
        dd = copy.copy(d)
        with jit.use(compiled):
            project_twist(L, dd)
        runs.append((dd.qpos.copy(), dd.qvel.copy()))
    (q0, v0), (q1, v1) = runs
    assert np.array_equal(q0, q1) and np.array_equal(v0, v1)
    changed = np.any(q0[qi] != d.qpos[qi], axis=1)
    assert 0 < changed.sum() < len(L.ball_q)  # some clamped, some within their range
    assert np.any(v0 != d.qvel)  # outward twist velocities removed
    assert np.any(v0[L.ball_d][changed] == d.qvel[L.ball_d][changed])  # inward ones kept


def test_read_kernel_reads_the_poses_the_numpy_path_reads(skeleton: Skeleton) -> None:
    """Joints in random, unnormalised rotations (hinges at random angles): both paths read the same roots
    and rotations, bit for bit.

    Broken in the kernel by leaving the rotations unnormalised, or by reading each hinge's angle from
    the next hinge's ``qpos``: the arrays then differ."""
    pw = _world(skeleton)
    pw.step()
    L, d = pw.layout, pw.data
    assert L is not None and d is not None
    rng = np.random.default_rng(4)
    d.qpos[:] = rng.normal(0, 1, len(d.qpos))
    with jit.use(False):
        want = read_poses(L, d)
    with jit.use(True):
        got = read_poses(L, d)
    assert np.array_equal(want[0], got[0]) and np.array_equal(want[1], got[1])
    assert len(L.hinge_q) and not np.allclose(got[1][L.hinge_src], quat.identity(len(L.hinge_q)))


def test_load_compiles_the_signatures_the_steps_use(skeleton: Skeleton) -> None:
    """:func:`~engine.ragdoll._drive_kernel.load` (run when the world compiles its model) gives each kernel
    the argument types of the real calls, so a step loads nothing more: one signature each after stepping.

    Broken by a float array where the kernel gets MuJoCo's boolean ``eq_active`` (``f`` for the ``b`` in
    ``load``): the first step then compiles a second signature of ``drive_kernel``."""
    from engine.ragdoll import _drive_kernel as K

    with jit.use(True):
        pw = _world(skeleton)
        pw.step()  # compiles the model: loads the kernels
        pw.step()
        L, d = pw.layout, pw.data
        assert L is not None and d is not None
        read_poses(L, d)
    for kernel in (K.drive_kernel, K.twist_kernel, K.read_kernel):
        assert len(cast(Any, kernel).signatures) == 1, kernel  # numba's dispatcher
