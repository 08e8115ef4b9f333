"""Keyframe tracks: periodic splines join at the seam, one-shot tracks never overshoot."""

from __future__ import annotations

import numpy as np
import pytest

from engine.clips._keys import one_shot, periodic, smoothstep


def test_periodic_passes_through_keys_and_joins_smoothly_at_the_seam() -> None:
    keys = ((0.1, 1.0), (0.4, 3.0), (0.8, -2.0))
    np.testing.assert_allclose(periodic(keys, [0.1, 0.4, 0.8])[:, 0], [1.0, 3.0, -2.0], atol=1e-12)
    eps = 1e-6
    before, after = periodic(keys, [1.0 - eps, 1.0 + eps])[:, 0]
    at0 = periodic(keys, [0.0])[0, 0]
    assert abs(before - at0) < 1e-4 and abs(after - at0) < 1e-4
    slope_l = (periodic(keys, [1.0])[0, 0] - periodic(keys, [1.0 - 1e-4])[0, 0]) / 1e-4
    slope_r = (periodic(keys, [1e-4])[0, 0] - periodic(keys, [0.0])[0, 0]) / 1e-4
    assert abs(slope_l - slope_r) < 1e-2 * max(1.0, abs(slope_l))


def test_periodic_vector_keys_and_single_key() -> None:
    out = periodic(((0.0, (1.0, 2.0, 3.0)), (0.5, (0.0, 0.0, 0.0))), np.linspace(0, 1, 7))
    assert out.shape == (7, 3)
    np.testing.assert_allclose(periodic(((0.3, 5.0),), [0.0, 0.9])[:, 0], [5.0, 5.0])


def test_bad_keys_are_rejected() -> None:
    with pytest.raises(ValueError):
        periodic(((0.2, 1.0), (1.2, 2.0)), [0.0])  # 1.2 wraps onto 0.2
    with pytest.raises(ValueError):
        periodic((), [0.0])
    with pytest.raises(ValueError):
        one_shot(((0.0, 1.0), (0.0, 2.0)), [0.0])
    with pytest.raises(ValueError):
        periodic(((0.0, 1.0), (0.5, (1.0, 2.0))), [0.0])


def test_one_shot_hits_keys_holds_ends_and_does_not_overshoot() -> None:
    keys = ((0.0, 0.1), (0.5, 0.1), (1.0, 0.9), (1.5, 0.95))
    t = np.linspace(-0.5, 2.0, 301)
    y = one_shot(keys, t)[:, 0]
    assert y.min() >= 0.1 - 1e-12 and y.max() <= 0.95 + 1e-12
    np.testing.assert_allclose(one_shot(keys, [0.0, 0.5, 1.0, 1.5])[:, 0], [0.1, 0.1, 0.9, 0.95])
    assert y[0] == pytest.approx(0.1) and y[-1] == pytest.approx(0.95)


def test_smoothstep_eases() -> None:
    np.testing.assert_allclose(smoothstep([-1.0, 0.0, 0.5, 1.0, 2.0]), [0.0, 0.0, 0.5, 1.0, 1.0])
