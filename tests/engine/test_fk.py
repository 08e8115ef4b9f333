"""Batched FK against a reference written one joint at a time with scipy."""

import numpy as np
from scipy.spatial.transform import Rotation

from engine import quat
from engine.fk import forward_kinematics, world_points
from engine.humanoid import humanoid_skeleton


def reference_fk(sk, root, rots):
    n = sk.num_joints
    R = [None] * n
    P = np.zeros((n, 3))
    for j in range(n):
        local = Rotation.from_quat(quat.to_xyzw(rots[j]))
        if sk.parents[j] < 0:
            R[j], P[j] = local, root
        else:
            p = sk.parents[j]
            R[j] = R[p] * local
            P[j] = P[p] + R[p].apply(np.array(sk.offsets[j]))
    return P, np.stack([quat.from_xyzw(r.as_quat()) for r in R])


def test_rest_pose_positions():
    sk = humanoid_skeleton()
    pos, _ = forward_kinematics(sk, sk.offsets[0], quat.identity(sk.num_joints))
    assert np.allclose(pos[sk.index("head")], [0, 1.55, 0])
    tips = world_points(sk, pos, quat.identity(sk.num_joints))
    assert abs(tips[sk.index("l_foot"), 1]) < 0.02  # toes on the ground


def test_batched_fk_matches_reference_for_many_puppets():
    sk = humanoid_skeleton()
    rng = np.random.default_rng(3)
    rots = quat.exp(rng.normal(scale=0.5, size=(5, sk.num_joints, 3)))
    roots = rng.normal(size=(5, 3))
    pos, rot = forward_kinematics(sk, roots, rots)
    for k in range(5):
        p_ref, r_ref = reference_fk(sk, roots[k], rots[k])
        np.testing.assert_allclose(pos[k], p_ref, atol=1e-12)
        np.testing.assert_allclose(quat.align_hemisphere(rot[k]), quat.align_hemisphere(r_ref), atol=1e-12)


def test_per_puppet_offsets():
    sk = humanoid_skeleton()
    offsets = np.stack([sk.offsets, sk.offsets * 2.0])
    pos, _ = forward_kinematics(sk, np.zeros((2, 3)), quat.identity(2, sk.num_joints), offsets)
    np.testing.assert_allclose(pos[1], pos[0] * 2.0, atol=1e-12)
