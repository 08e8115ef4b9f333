"""Pose blending: weighted quaternion means, additive layers, cross-fades."""

from __future__ import annotations

import numpy as np
import pytest

from engine import quat
from engine.blend import additive_delta, apply_additive, blend, blend_quaternions, crossfade, fade_weight
from engine.pose import Pose

RNG = np.random.default_rng(7)


def _pose(j: int = 5, scale: float = 0.5) -> Pose:
    return Pose(RNG.normal(size=3), quat.exp(RNG.normal(scale=scale, size=(j, 3))))


def _same_rotation(a: np.ndarray, b: np.ndarray, tol: float = 1e-9) -> bool:
    return bool(np.all(np.abs(np.abs(np.sum(a * b, axis=-1)) - 1.0) < tol))


def test_blend_of_copies_is_the_pose_and_weights_are_normalised() -> None:
    p = _pose()
    out = blend(np.array([2.0, 3.0]), [p, p])
    assert np.allclose(out.root, p.root)
    assert _same_rotation(out.rotations, p.rotations)


def test_two_pose_blend_follows_the_slerp_path_and_ignores_sign() -> None:
    a, b = _pose(), _pose()
    flipped = Pose(b.root, -b.rotations)
    mid = blend([0.5, 0.5], [a, flipped])
    assert _same_rotation(mid.rotations, quat.slerp(a.rotations, b.rotations, 0.5), 1e-9)
    assert np.allclose(mid.root, 0.5 * (a.root + b.root))


def test_karcher_mean_is_order_independent_and_exact_for_two() -> None:
    qs = quat.exp(RNG.normal(scale=1.0, size=(4, 3)))
    w = np.array([0.1, 0.4, 0.2, 0.3])
    m1 = blend_quaternions(w, qs, method="mean", iterations=20)
    m2 = blend_quaternions(w[::-1], qs[::-1], method="mean", iterations=20)
    assert _same_rotation(m1, m2, 1e-9)
    two = blend_quaternions([0.3, 0.7], qs[:2], method="mean", iterations=20)
    assert _same_rotation(two, quat.slerp(qs[0], qs[1], 0.7), 1e-9)
    # the Karcher mean's residual (weighted tangent vectors) vanishes
    resid = np.sum(w[:, None] * quat.log(quat.mul(quat.conjugate(m1), qs)), axis=0)
    assert np.linalg.norm(resid) < 1e-8


def test_batched_weights_blend_each_element() -> None:
    poses = Pose(RNG.normal(size=(6, 3, 3)), quat.exp(RNG.normal(scale=0.4, size=(6, 5, 3, 3))))
    # stacked: root [B=6, K=3, 3]; rotations [B=6, J=5, K=3, 4] -> move clip axis before joints
    stacked = Pose(poses.root, np.moveaxis(poses.rotations, 2, 1))
    w = RNG.random((6, 3))
    out = blend(w, stacked)
    for i in range(6):
        one = blend(w[i], [Pose(poses.root[i, k], poses.rotations[i, :, k]) for k in range(3)])
        assert np.allclose(out.root[i], one.root)
        assert _same_rotation(out.rotations[i], one.rotations)


@pytest.mark.parametrize("weights", [[0.0, 0.0], [1.0], [np.nan, 1.0]])
def test_bad_weights_are_rejected(weights: list[float]) -> None:
    with pytest.raises(ValueError):
        blend(weights, [_pose(), _pose()])


def test_mismatched_skeletons_and_unknown_method_are_rejected() -> None:
    with pytest.raises(ValueError, match="joint counts"):
        blend([1, 1], [_pose(4), _pose(5)])
    with pytest.raises(ValueError, match="method"):
        blend([1, 1], [_pose(), _pose()], method="cubic")


def test_additive_layer_round_trip_and_partial_weight() -> None:
    base, target = _pose(), _pose()
    delta = additive_delta(target, base)
    full = apply_additive(base, delta, 1.0)
    assert np.allclose(full.root, target.root)
    assert _same_rotation(full.rotations, target.rotations, 1e-9)
    none = apply_additive(base, delta, 0.0)
    assert _same_rotation(none.rotations, base.rotations, 1e-9)
    mask = np.zeros(5)
    mask[2] = 1.0
    masked = apply_additive(base, delta, mask)
    assert _same_rotation(masked.rotations[2], target.rotations[2], 1e-9)
    assert _same_rotation(masked.rotations[0], base.rotations[0], 1e-9)


def test_crossfade_endpoints_and_smooth_weight() -> None:
    a, b = _pose(), _pose()
    assert _same_rotation(crossfade(a, b, 0.0).rotations, a.rotations)
    assert _same_rotation(crossfade(a, b, 1.0).rotations, b.rotations)
    w = [fade_weight(t, 0.2) for t in np.linspace(-0.1, 0.3, 41)]
    assert w[0] == 0.0 and w[-1] == 1.0
    assert np.all(np.diff(w) >= 0.0)
    assert fade_weight(0.0, 0.0) == 1.0
