"""The periodic time-warp QP of §5.2: constraints, period, monotonicity, seam, the optimum itself."""

from __future__ import annotations

import numpy as np
import pytest

from authoring.mocurves.timewarp import W_SOFT, W_STRONG, TimeWarp, TimeWarpError, _energy_rows


def reference_solution(n: int, period: float, constraints: dict[int, float]) -> np.ndarray:
    """The same energy minimised by dense least squares (valid when no inequality is active)."""
    times = np.arange(n + 1) * period / n
    pr, vel, speed = (m.toarray() for m in _energy_rows(n))
    rows = [np.sqrt(W_STRONG) * pr, np.sqrt(W_SOFT) * vel, np.sqrt(W_SOFT) * speed]
    rhs = [np.sqrt(W_STRONG) * np.array([period]), np.sqrt(W_SOFT) * np.diff(times), np.zeros(n)]
    for i, t in constraints.items():
        for k, v in ((i, t), (n, t + period)) if i == 0 else ((i, t),):
            row = np.zeros((1, n + 1))
            row[0, k] = np.sqrt(W_STRONG)
            rows.append(row)
            rhs.append(np.array([np.sqrt(W_STRONG) * v]))
    return np.linalg.lstsq(np.vstack(rows), np.concatenate(rhs), rcond=None)[0]


@pytest.mark.parametrize("n", [30, 120])
def test_constraints_met_period_kept_monotonic(n):
    tw = TimeWarp(n, 1.2)
    cons = {n // 5: 0.3, n // 2: 0.5}
    t = tw.solve(cons)
    assert t.shape == (n + 1,)
    for i, v in cons.items():
        assert t[i] == pytest.approx(v, abs=2e-4)
    assert t[n] - t[0] == pytest.approx(1.2, abs=2e-4)
    assert np.all(np.diff(t) >= 0.0)
    # Keypoint n//5 was at 0.24 s and now shows 0.3 s: the motion before it speeds up.
    assert np.diff(t)[: n // 5].mean() > 1.2 / n


def test_matches_dense_least_squares_optimum():
    n, period = 40, 1.0
    cons = {5: 0.15, 30: 0.74}
    t = TimeWarp(n, period).solve(cons)
    ref = reference_solution(n, period, cons)
    assert np.all(np.diff(ref) > 0)  # inequalities inactive: the optima must agree
    np.testing.assert_allclose(t, ref, atol=2e-5)


def test_monotonic_when_the_drag_asks_for_time_to_run_backwards():
    n = 30
    tw = TimeWarp(n, 1.0)
    # Keypoint 10 pinned at its own time, keypoint 12 asked to show what keypoint 4 showed.
    t = tw.solve({10: 10 / n, 12: 4 / n})
    gaps = np.diff(t)
    assert np.all(gaps >= 0.0)
    assert gaps[10:12].max() < 1e-3  # the inequality is what holds them, not the energies
    assert t[n] - t[0] == pytest.approx(1.0, abs=1e-3)


def test_periodic_across_the_seam():
    """The seam is a keypoint like any other: shifting the drag shifts the warp, nothing else."""
    n, period = 48, 1.0
    tw = TimeWarp(n, period)
    base = tw.solve({10: 10 / n + 0.05})
    gaps = np.diff(base)
    for shift in (20, 38, 41):  # 38 + 10 = 48: the dragged keypoint lands on the seam (0)
        k = (10 + shift) % n
        t = TimeWarp(n, period).solve({k: k / n + 0.05})
        np.testing.assert_allclose(np.diff(t), np.roll(gaps, shift), atol=2e-5)


def test_drag_across_the_seam_is_unwrapped():
    n = 20
    t = TimeWarp(n, 1.0).solve({1: 0.98})  # keypoint 1 (0.05 s) to just before the seam
    assert t[1] == pytest.approx(-0.02, abs=2e-4)
    assert np.all(np.diff(t) >= 0)


def test_warm_started_drags_match_cold_solves():
    n = 120
    warm = TimeWarp(n, 2.0)
    for step in range(6):
        cons = {30: 0.5 + 0.02 * step, 90: 1.5}
        t = warm.solve(cons)
        np.testing.assert_allclose(t, TimeWarp(n, 2.0).solve(cons), atol=2e-5)


def test_no_constraint_is_the_identity_and_bad_input_is_refused():
    tw = TimeWarp(10, 1.0)
    np.testing.assert_array_equal(tw.solve({}), tw.times)
    with pytest.raises(TimeWarpError):
        tw.solve({10: 0.5})
    with pytest.raises(TimeWarpError):
        tw.solve({3: float("nan")})
    with pytest.raises(TimeWarpError):
        TimeWarp(2, 1.0)
