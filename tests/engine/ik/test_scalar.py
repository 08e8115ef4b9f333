"""The float kernels of the per-frame IK agree with their numpy counterparts in engine.quat / engine.fk."""

from __future__ import annotations

import numpy as np
import pytest

from engine import quat
from engine.fk import forward_kinematics
from engine.humanoid import humanoid_skeleton
from engine.ik import _scalar as s


def _quats(rng, n):
    return quat.normalize(rng.normal(size=(n, 4)))


def test_products_rotations_and_axis_angles_match_engine_quat():
    rng = np.random.default_rng(5)
    a, b = _quats(rng, 20), _quats(rng, 20)
    v, axes, angles = rng.normal(size=(20, 3)), rng.normal(size=(20, 3)), rng.uniform(-4, 4, 20)
    for i in range(20):
        assert np.allclose(s.qmul(tuple(a[i]), tuple(b[i])), quat.mul(a[i], b[i]), atol=1e-15)
        assert np.allclose(s.qrot(tuple(a[i]), tuple(v[i])), quat.rotate(a[i], v[i]), atol=1e-14)
        assert np.allclose(s.from_axis_angle(tuple(axes[i]), angles[i]), quat.from_axis_angle(axes[i], angles[i]))
        assert np.allclose(s.qnormalize(tuple(3.0 * a[i])), a[i], atol=1e-15)
        for t in (0.0, 0.3, 1.0):
            assert np.allclose(s.slerp(tuple(a[i]), tuple(b[i]), t), quat.slerp(a[i], b[i], t), atol=1e-12)
    assert s.qnormalize((0.0, 0.0, 0.0, 0.0)) == s.Q_ID
    assert s.slerp(tuple(a[0]), tuple(a[0]), 0.5) == pytest.approx(tuple(a[0]), abs=1e-12)  # the small-angle branch


@pytest.mark.parametrize(
    ("u", "v"),
    [((0.3, 1.0, -0.2), (0.0, 1.0, 0.0)), ((1.0, 0.0, 0.0), (-1.0, 0.0, 0.0)), ((0.0, 0.0, 2.0), (0.0, 0.0, -1.0))],
)
def test_between_matches_including_opposite_directions(u, v):
    q = s.between(u, v)
    assert np.allclose(q, quat.between(u, v), atol=1e-12)
    assert np.allclose(s.qrot(q, np.divide(u, np.linalg.norm(u))), np.divide(v, np.linalg.norm(v)), atol=1e-12)
    assert s.between((0.0, 0.0, 0.0), v) == s.Q_ID  # a degenerate direction: numpy gives the identity too


def test_frames_match_the_matrix_route_in_every_shepperd_branch():
    rng = np.random.default_rng(9)
    local = ((-1.0, 0.0, 0.0), (0.0, -1.0, 0.0))

    def frame(a, b):
        a = a / np.linalg.norm(a)
        b = b - np.dot(a, b) * a
        b = b / np.linalg.norm(b)
        return np.stack([a, b, np.cross(a, b)], axis=-1)

    branches = set()
    for _ in range(200):
        x, y = rng.normal(size=3), rng.normal(size=3)
        m = frame(x, y) @ frame(np.array(local[0]), np.array(local[1])).T
        branches.add(int(np.argmax([np.trace(m), m[0, 0], m[1, 1], m[2, 2]])))
        q = s.from_frames((tuple(x), tuple(y)), local)
        assert np.allclose(q, quat.from_matrix(m), atol=1e-12)
        assert q[0] >= 0.0
    assert branches == {0, 1, 2, 3}


def test_chain_fk_matches_forward_kinematics_with_and_without_offsets():
    sk = humanoid_skeleton()
    rng = np.random.default_rng(2)
    rot = _quats(rng, 17)
    root = np.array([0.4, 0.9, -1.2])
    offsets = sk.offsets * 1.3
    for off in (None, offsets):
        wp, wr = forward_kinematics(sk, root, rot, off)
        o = (sk.offsets if off is None else off).tolist()
        for joint in ("l_hand", "r_foot", "head"):
            j = sk.index(joint)
            pos, rots = s.chain_fk(sk.parents, tuple(root), rot.tolist(), o, j)
            assert list(pos) == sk.chain(0, j)
            assert np.allclose(pos[j], wp[j], atol=1e-12) and np.allclose(rots[j], wr[j], atol=1e-12)
