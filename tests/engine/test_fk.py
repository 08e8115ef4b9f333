"""Batched FK against a reference written one joint at a time with scipy."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from engine import jit, quat
from engine.fk import fk_kernel, fk_rows, forward_kinematics, world_points
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
    own, _ = forward_kinematics(sk, np.zeros(3), quat.identity(sk.num_joints))
    # Found by the mutation run: offsets read as NaN passed, as assert_allclose takes NaN == NaN.
    assert np.all(np.isfinite(pos))
    np.testing.assert_allclose(pos[0], own, atol=1e-12)
    np.testing.assert_allclose(pos[1], pos[0] * 2.0, atol=1e-12)


def reference_fk_scaled(sk, root, rots, scales):
    """One joint at a time: a joint's world scale is its parent's times its own, and scales every bone below it."""
    n = sk.num_joints
    R, S, P = [None] * n, np.ones(n), np.zeros((n, 3))
    for j in range(n):
        local = Rotation.from_quat(quat.to_xyzw(rots[j]))
        p = sk.parents[j]
        if p < 0:
            R[j], S[j], P[j] = local, scales[j], root
        else:
            R[j], S[j] = R[p] * local, S[p] * scales[j]
            P[j] = P[p] + R[p].apply(S[p] * np.array(sk.offsets[j]))
    return P


def test_scales_on_joints_with_children_reach_every_descendant():
    """Scale channels on inner joints (spine, chest, an upper arm, a thigh): each scales all bones below it.

    Shown to fail when broken: scaling each offset by the joint's *own* scale (``wscale[..., idx]``
    instead of its parent's), or not accumulating the scale down the levels (dropping the
    ``wscale[..., idx] *= wscale[..., par]`` loop), both move the hands, head and feet off the reference.
    """
    sk = humanoid_skeleton()
    rng = np.random.default_rng(8)
    rots = quat.exp(rng.normal(scale=0.4, size=(3, sk.num_joints, 3)))
    roots = rng.normal(size=(3, 3))
    scales = np.ones((3, sk.num_joints))
    for name, s in (("spine", 1.3), ("chest", 0.8), ("l_upper_arm", 1.5), ("r_upper_leg", 0.7)):
        scales[:, sk.index(name)] = s
    scales[2] = rng.uniform(0.5, 2.0, sk.num_joints)
    pos, _ = forward_kinematics(sk, roots, rots, scales=scales)
    for k in range(3):
        np.testing.assert_allclose(pos[k], reference_fk_scaled(sk, roots[k], rots[k], scales[k]), atol=1e-12)
    # Read directly: the upper arm's 1.5 lengthens the forearm bone (upper arm -> elbow is the arm's own
    # offset, scaled by the chest's 0.8 x spine's 1.3), and the hand bone below it by 1.5 as well.
    plain, _ = forward_kinematics(sk, roots[0], rots[0])
    ua, la, hand = sk.index("l_upper_arm"), sk.index("l_lower_arm"), sk.index("l_hand")
    assert np.linalg.norm(pos[0, la] - pos[0, ua]) == pytest.approx(
        1.5 * 1.3 * 0.8 * np.linalg.norm(plain[la] - plain[ua])
    )
    assert np.linalg.norm(pos[0, hand] - pos[0, la]) == pytest.approx(
        1.5 * 1.3 * 0.8 * np.linalg.norm(plain[hand] - plain[la])
    )


def test_inputs_of_any_float_type_are_computed_in_double_precision():
    """float32 poses (a GPU buffer, a float32 file) give the float64 answer: the inputs are widened first.

    Found by the mutation run: dropping ``dtype=np.float64`` on the scales survived (on the other inputs it
    is equivalent: ``quat`` widens them itself)."""
    sk = humanoid_skeleton()
    rng = np.random.default_rng(5)
    rots = quat.exp(rng.normal(scale=0.5, size=(sk.num_joints, 3))).astype(np.float32)
    root = rng.normal(size=3).astype(np.float32)
    offsets = (sk.offsets * 1.1).astype(np.float32)
    scales = rng.uniform(0.5, 2.0, sk.num_joints).astype(np.float32)
    pos, rot = forward_kinematics(sk, root, rots, offsets, scales)
    ref, ref_rot = forward_kinematics(
        sk, root.astype(np.float64), rots.astype(np.float64), offsets.astype(np.float64), scales.astype(np.float64)
    )
    assert pos.dtype == np.float64 and rot.dtype == np.float64
    np.testing.assert_allclose(pos, ref, atol=1e-12)
    np.testing.assert_allclose(rot, ref_rot, atol=1e-12)


@pytest.mark.skipif(not jit.AVAILABLE, reason="numba not installed: there are no compiled kernels")
def test_the_rows_kernel_is_the_batch_kernel_at_other_rows_bit_for_bit() -> None:
    """:func:`fk_rows` (the FK stage's pass on the columns) and :func:`fk_kernel` (``forward_kinematics``) run
    one per-puppet function: the same puppets read from and written to shuffled rows give the same bits, the
    previous values are copied aside first, and both agree with the numpy path to 1e-12.

    Broken once by reading the offsets at the output row (``off[o]`` instead of ``off[p]``) in the shared
    function: the shuffled rows' positions differ and it fails."""
    sk = humanoid_skeleton()
    rng = np.random.default_rng(12)
    count = 40
    rots = quat.exp(rng.normal(scale=0.6, size=(count, sk.num_joints, 3)))
    roots = rng.normal(size=(count, 3))
    offsets = sk.offsets * rng.uniform(0.5, 1.5, size=(count, sk.num_joints, 1))
    pos, rot = np.empty((count, sk.num_joints, 3)), np.empty((count, sk.num_joints, 4))
    fk_kernel(sk.parents, roots, rots, offsets, pos, rot)
    with jit.use(False):
        numpy_pos, numpy_rot = forward_kinematics(sk, roots, rots, offsets)
    np.testing.assert_allclose(pos, numpy_pos, atol=1e-12)
    np.testing.assert_allclose(rot, numpy_rot, atol=1e-12)
    rows, out_rows = rng.permutation(count), rng.permutation(count)
    inverse = np.empty(count, dtype=np.int64)
    inverse[rows] = np.arange(count)
    at_rows = (roots[inverse], rots[inverse])  # puppet p's pose at row rows[p]
    out_pos, out_rot = rng.normal(size=pos.shape), rng.normal(size=rot.shape)
    before = (out_pos.copy(), out_rot.copy())
    prev_pos, prev_rot = np.empty_like(out_pos), np.empty_like(out_rot)
    fk_rows(sk.parents, rows, *at_rows, offsets, out_rows, out_pos, out_rot, prev_pos, prev_rot)
    assert out_pos[out_rows].tobytes() == pos.tobytes() and out_rot[out_rows].tobytes() == rot.tobytes()
    np.testing.assert_array_equal(prev_pos, before[0])
    np.testing.assert_array_equal(prev_rot, before[1])
