"""The IK rig's coordinates round-trip poses, and its analytic Jacobians match finite differences."""

from __future__ import annotations

import numpy as np
import pytest

from engine import quat
from engine.humanoid import humanoid_skeleton
from engine.ik import HINGE, IKRig, humanoid_rig
from engine.ik._fk import fk_matrices
from engine.ik.jacobian import dof_axes, orientation_jacobian, point_jacobian


def test_coordinates_round_trip_including_hinge_swing():
    sk = humanoid_skeleton()
    rig = humanoid_rig(sk, root_translation=True)
    rng = np.random.default_rng(0)
    rot = quat.exp(rng.normal(scale=0.6, size=(sk.num_joints, 3)))
    root = rng.normal(size=3)
    c, pre = rig.to_coordinates(root, rot)
    r2, q2 = rig.to_pose(c, pre, np.zeros(3))
    assert np.allclose(r2, root)
    assert np.allclose(quat.angle_between(q2, rot), 0.0, atol=1e-6)
    assert rig.kinds[sk.index("l_lower_leg")] == HINGE
    assert rig.num_dofs == 3 + 3 * 13 + 4


def test_analytic_jacobian_matches_finite_differences():
    sk = humanoid_skeleton()
    rig = humanoid_rig(sk, root_translation=True)
    rng = np.random.default_rng(1)
    c, pre = rig.to_coordinates(np.array([0.0, 0.95, 0.0]), quat.exp(rng.normal(scale=0.5, size=(17, 3))))
    frames = np.array([sk.index("l_hand"), sk.index("r_foot"), sk.index("head")])
    local = np.array([[0.0, -0.09, 0.0], [0.0, -0.05, 0.15], [0.0, 0.2, 0.0]])

    def state(cc):
        r, q = rig.to_pose(cc, pre, np.zeros(3))
        wp, wm = fk_matrices(sk, r, q)
        return wp, wm, wp[frames] + np.einsum("nij,nj->ni", wm[frames], local)

    wp, wm, pts = state(c)
    axes = dof_axes(rig, c, wm)
    jp = point_jacobian(rig, axes, wp, frames, pts)
    jo = orientation_jacobian(rig, axes, frames)
    h = 1e-6
    for k in range(rig.num_dofs):
        d = np.zeros_like(c)
        d[k] = h
        wp2, wm2, pts2 = state(c + d)
        assert np.allclose((pts2 - pts).reshape(-1) / h, jp[:, k], atol=1e-4)
        # world angular velocity from the matrix derivative: (dR Rᵀ) is skew
        w = np.einsum("nij,nkj->nik", (wm2[frames] - wm[frames]) / h, wm[frames])
        omega = np.stack([w[:, 2, 1], w[:, 0, 2], w[:, 1, 0]], axis=-1)
        assert np.allclose(omega.reshape(-1), jo[:, k], atol=1e-4)


def test_build_rejects_bad_specs():
    sk = humanoid_skeleton()
    with pytest.raises(KeyError, match="no joint"):
        IKRig.build(sk, hinges={"tail": (1, 0, 0)})
    with pytest.raises(ValueError, match="lower limit"):
        IKRig.build(sk, limits={"spine": (1.0, -1.0)})
    with pytest.raises(ValueError, match="non-zero axis"):
        IKRig.build(sk, hinges={"l_lower_leg": (0, 0, 0)})


def test_fk_of_a_new_skeleton_ignores_a_freed_one_with_the_same_joint_count():
    # The pointer-jumping table is cached per hierarchy; a skeleton freed and replaced by
    # another of as many joints (CPython reuses the id) must not inherit the old table.
    from engine.fk import forward_kinematics
    from engine.skeleton import Skeleton

    n = 6
    rng = np.random.default_rng(2)
    offsets = rng.normal(scale=0.1, size=(n, 3))
    rot = quat.exp(rng.normal(scale=0.5, size=(n, 3)))
    for trial in range(20):
        parents = np.array([-1, 0, 1, 2, 3, 4]) if trial % 2 else np.array([-1, 0, 0, 0, 0, 0])
        sk = Skeleton(tuple(f"j{i}" for i in range(n)), parents, offsets, np.zeros((n, 3)))
        wp, _ = fk_matrices(sk, np.zeros(3), rot)
        ref, _ = forward_kinematics(sk, np.zeros(3), rot)
        assert np.allclose(wp, ref, atol=1e-12), f"trial {trial}: FK used another hierarchy's table"
        del sk
