"""The physics step's level of detail: a crowd in the model steps coarser, a few ragdolls as before.

Broken once to see these fail: ``CROWD = 100`` (no crowd resolution) fails the first test; restoring
only the timestep on the way back (not the armature) fails it too; ``CROWD = 2`` fails the second.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from engine import quat
from engine.ragdoll._detail import ARMATURE
from engine.ragdoll.physics import PhysicsWorld
from engine.skeleton import Skeleton
from tests.engine.ragdoll.test_pool import _crowd as _world


def _drive(pw: PhysicsWorld, skeleton: Skeleton, limp: int) -> None:
    """The first ``limp`` ragdolls go limp (simulated); the others stand animated, too far apart to touch."""
    rot = quat.identity(skeleton.num_joints)
    for k in pw.ragdoll_keys:
        root = np.array([6.0 * (k - 1), 1.0, 0.0])
        if k <= limp:
            pw.drive(k, root, rot, 0.0, 0.0)
        else:
            pw.drive(k, root, rot, 1.0, 1.0, kinematic=True)


def _joint_dofs(m: mujoco.MjModel) -> np.ndarray:
    kind = m.jnt_type[m.dof_jntid]
    return np.asarray((kind == mujoco.mjtJoint.mjJNT_BALL) | (kind == mujoco.mjtJoint.mjJNT_HINGE))


def test_a_crowd_in_the_model_steps_in_fewer_substeps_and_a_few_ragdolls_as_compiled(skeleton: Skeleton) -> None:
    pw = _world(skeleton, 10)
    _drive(pw, skeleton, 7)  # seven simulated: a few
    pw.step()
    m, d = pw.model, pw.data
    assert m is not None and d is not None
    compiled_step, compiled_armature = m.opt.timestep, m.dof_armature.copy()
    assert pw.detail.current == pw.substeps == 8 and compiled_step == pw.timestep
    _drive(pw, skeleton, 8)  # eight: a crowd
    t0 = d.time
    pw.step()
    assert pw.detail.current == 5 and m.opt.timestep == pytest.approx(pw.dt / 5)
    assert d.time - t0 == pytest.approx(pw.dt)  # a step is still one world step long
    joint = _joint_dofs(m)
    assert (m.dof_armature[joint] >= ARMATURE).all()
    assert np.array_equal(m.dof_armature[~joint], compiled_armature[~joint])  # free joints (roots) untouched
    assert (m.dof_armature[joint] > compiled_armature[joint]).any()  # the hands' wrists were lighter
    _drive(pw, skeleton, 7)
    pw.step()
    assert pw.detail.current == 8
    assert m.opt.timestep == compiled_step and np.array_equal(m.dof_armature, compiled_armature)  # bit for bit


def test_a_few_ragdolls_never_leave_the_compiled_resolution(skeleton: Skeleton) -> None:
    pw = _world(skeleton, 3)
    _drive(pw, skeleton, 3)
    pw.step()
    m = pw.model
    assert m is not None
    compiled = m.dof_armature.copy()
    for _ in range(5):
        pw.step()
        assert pw.detail.current == 8 and m.opt.timestep == pw.timestep
    assert np.array_equal(m.dof_armature, compiled)
