"""The physics stage's batched calls for simulated ragdolls give, number for number, what the
one-ragdoll calls give: driving, reading back and blending ten fallers at once instead of one by one."""

from __future__ import annotations

import numpy as np
import pytest

from engine import quat
from engine.pose import Pose
from engine.ragdoll import default_profile
from engine.ragdoll.blend import blend_poses, blend_rows
from engine.ragdoll.physics import PhysicsWorld
from engine.skeleton import Skeleton


def _world(skeleton: Skeleton, n: int) -> PhysicsWorld:
    pw = PhysicsWorld()
    for k in range(n):
        pw.add_ragdoll(
            k + 1, skeleton, default_profile(skeleton), [1.5 * k, 1.0, 0.0], quat.identity(skeleton.num_joints)
        )
    return pw


def _targets(skeleton: Skeleton, n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    roots = np.array([[1.5 * k, 1.0, 0.0] for k in range(n)]) + rng.normal(0, 0.05, (n, 3))
    rot = quat.identity(n * skeleton.num_joints) + rng.normal(0, 0.2, (n * skeleton.num_joints, 4))
    return roots, rot  # not normalised: the drive does that


def test_drive_simulated_sets_the_commands_drive_sets(skeleton: Skeleton) -> None:
    """Broken by not normalising the rotations, or by clipping no weight: the columns then differ."""
    n, J = 3, skeleton.num_joints
    roots, rot = _targets(skeleton, n, 1)
    muscle, pin = np.array([0.2, 1.4, 0.0]), np.array([1.0, 0.3, -0.5])
    one, many = _world(skeleton, n), _world(skeleton, n)
    for k in range(n):
        one.drive(k + 1, roots[k], rot[k * J : (k + 1) * J], muscle[k], pin[k], muscle[k] * pin[k])
    many.drive_simulated([1, 2, 3], roots, rot, muscle, pin, muscle * pin)
    a, b = one.commands, many.commands
    for name in ("root", "rot", "muscle", "pin", "support", "kinematic"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    bad = rot.copy()
    bad[J + 2, 1] = np.nan
    with pytest.raises(ValueError, match="ragdoll 2"):
        many.drive_simulated([1, 2, 3], roots, bad, muscle, pin, muscle * pin)


def test_simulated_state_is_what_each_query_answers(skeleton: Skeleton) -> None:
    """Broken by reading the root velocity from the wrong dofs (``root_d + 1``), or the rotations of
    another ragdoll: the arrays then differ from the single queries."""
    n, J = 3, skeleton.num_joints
    pw = _world(skeleton, n)
    roots, rot = _targets(skeleton, n, 2)
    pw.drive(3, roots[2], rot[2 * J :], 1.0, 1.0, kinematic=True)  # animated, far from the others: out of the model
    pw.drive_simulated([1, 2], roots[:2], rot[: 2 * J], np.array([0.0, 0.5]), np.zeros(2), np.zeros(2))
    for _ in range(5):
        pw.step()
    assert pw.in_model(1) and pw.in_model(2) and not pw.in_model(3)
    root, r, vel, ke = pw.simulated_state([1, 2, 3])
    for k in range(n):
        pose = pw.pose(k + 1)
        assert np.array_equal(root[k], pose.root) and np.array_equal(r[k * J : (k + 1) * J], pose.rotations)
        assert np.array_equal(vel[k], pw.root_velocity(k + 1)) and ke[k] == pw.kinetic_energy(k + 1)
    assert ke[0] > 0.0 and ke[2] == 0.0


def test_blend_rows_is_blend_poses_pose_by_pose(skeleton: Skeleton) -> None:
    """Weights 0, 1 (exact copies) and between (slerp). Broken by blending with one shared weight or
    by taking the formula at weight 1 (not bit for bit the simulated pose)."""
    n, J = 4, skeleton.num_joints
    rng = np.random.default_rng(3)
    root, sim_root = rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    rot, sim_rot = (quat.normalize(rng.normal(size=(n * J, 4))) for _ in range(2))
    w = np.array([0.0, 1.0, 0.25, 0.7])
    out_root, out_rot = blend_rows(root, rot, sim_root, sim_rot, w, np.full(n, J))
    for k in range(n):
        s = slice(k * J, (k + 1) * J)
        want = blend_poses(Pose(root[k], rot[s]), Pose(sim_root[k], sim_rot[s]), w[k])
        assert np.array_equal(out_root[k], want.root) and np.array_equal(out_rot[s], want.rotations), k
