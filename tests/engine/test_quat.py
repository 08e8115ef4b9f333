"""Quaternion helpers checked against scipy's Rotation."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation, Slerp

from engine import quat


@pytest.fixture
def rng():
    return np.random.default_rng(7)


def random_quats(rng, n):
    return quat.from_xyzw(Rotation.random(n, random_state=rng).as_quat())


def test_mul_matches_scipy_composition(rng):
    a, b = random_quats(rng, 50), random_quats(rng, 50)
    expected = (Rotation.from_quat(quat.to_xyzw(a)) * Rotation.from_quat(quat.to_xyzw(b))).as_quat()
    np.testing.assert_allclose(
        quat.align_hemisphere(quat.mul(a, b)), quat.align_hemisphere(quat.from_xyzw(expected)), atol=1e-12
    )


def test_rotate_matches_scipy(rng):
    q = random_quats(rng, 50)
    v = rng.normal(size=(50, 3))
    np.testing.assert_allclose(quat.rotate(q, v), Rotation.from_quat(quat.to_xyzw(q)).apply(v), atol=1e-12)


def test_matrix_round_trip_and_scipy(rng):
    q = random_quats(rng, 100)
    m = quat.to_matrix(q)
    np.testing.assert_allclose(m, Rotation.from_quat(quat.to_xyzw(q)).as_matrix(), atol=1e-12)
    np.testing.assert_allclose(quat.from_matrix(m), quat.align_hemisphere(q), atol=1e-12)


def test_log_exp_match_rotvec(rng):
    q = random_quats(rng, 100)
    rv = quat.log(q)
    np.testing.assert_allclose(rv, Rotation.from_quat(quat.to_xyzw(q)).as_rotvec(), atol=1e-10)
    np.testing.assert_allclose(quat.exp(rv), quat.align_hemisphere(q), atol=1e-12)
    assert np.allclose(quat.exp(np.zeros(3)), quat.IDENTITY)


def test_slerp_matches_scipy(rng):
    a, b = random_quats(rng, 1)[0], random_quats(rng, 1)[0]
    ts = np.linspace(0, 1, 11)
    ref = Slerp([0, 1], Rotation.from_quat(quat.to_xyzw(np.stack([a, b]))))(ts).as_quat()
    ours = np.stack([quat.slerp(a, b, t) for t in ts])
    np.testing.assert_allclose(quat.align_hemisphere(ours), quat.align_hemisphere(quat.from_xyzw(ref)), atol=1e-9)


@pytest.mark.parametrize("order", ["xyz", "zxy", "zyx", "yxz"])
def test_euler_matches_scipy_intrinsic(rng, order):
    ang = rng.uniform(-np.pi, np.pi, size=(20, 3))
    ours = quat.from_euler(order, ang)
    ref = quat.from_xyzw(Rotation.from_euler(order.upper(), ang).as_quat())
    np.testing.assert_allclose(quat.align_hemisphere(ours), quat.align_hemisphere(ref), atol=1e-12)
    np.testing.assert_allclose(
        quat.align_hemisphere(quat.from_euler(order, quat.to_euler(order, ours))),
        quat.align_hemisphere(ours),
        atol=1e-9,
    )


def test_swing_twist_recomposes_and_twist_is_about_axis(rng):
    q = random_quats(rng, 30)
    axis = np.array([0.0, 1.0, 0.0])
    swing, twist = quat.swing_twist(q, axis)
    np.testing.assert_allclose(quat.align_hemisphere(quat.mul(swing, twist)), quat.align_hemisphere(q), atol=1e-12)
    np.testing.assert_allclose(twist[:, [1, 3]], 0.0, atol=1e-12)
    # The swing moves the axis but has no component about it.
    np.testing.assert_allclose(np.sum(swing[:, 1:] * axis, axis=-1), 0.0, atol=1e-12)


def test_between_takes_u_to_v(rng):
    u, v = rng.normal(size=(20, 3)), rng.normal(size=(20, 3))
    q = quat.between(u, v)
    rotated = quat.rotate(q, u / np.linalg.norm(u, axis=1, keepdims=True))
    np.testing.assert_allclose(rotated, v / np.linalg.norm(v, axis=1, keepdims=True), atol=1e-12)
    opposite = quat.between([1.0, 0, 0], [-1.0, 0, 0])
    np.testing.assert_allclose(quat.rotate(opposite, [1.0, 0, 0]), [-1.0, 0, 0], atol=1e-12)


def test_normalize_zero_is_identity():
    assert np.allclose(quat.normalize(np.zeros(4)), quat.IDENTITY)
