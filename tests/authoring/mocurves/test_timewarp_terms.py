"""The time warp's energy read-out term by term on hand-made warps, and the solve's edges: a keypoint
asked for its own time, the seam keypoint, the minimum gap, what is refused and how.

The energies are worked out by hand from the module docstring's formulas (a shift, a stretch, one
keypoint bumped inside, at 0 and at the seam), not from the module's rows.
"""

from __future__ import annotations

import numpy as np
import pytest

from authoring.mocurves.timewarp import TimeWarp, TimeWarpError

N, T = 10, 1.0


def _tw() -> TimeWarp:
    return TimeWarp(N, T)


def test_the_original_times_cost_nothing() -> None:
    tw = _tw()
    assert tw.energy(tw.times, {}) == pytest.approx({"E_C": 0.0, "E_T": 0.0, "E_V": 0.0, "E_S": 0.0}, abs=1e-20)


def test_a_shift_costs_only_its_constraints() -> None:
    tw = _tw()
    e = tw.energy(tw.times + 0.05, {2: 0.2, 5: 0.5})
    assert e["E_C"] == pytest.approx(2 * 0.05**2) and e["E_T"] == pytest.approx(0.0, abs=1e-20)
    assert e["E_V"] == pytest.approx(0.0, abs=1e-20) and e["E_S"] == pytest.approx(0.0, abs=1e-20)


def test_a_stretch_changes_the_period_and_every_gap_evenly() -> None:
    tw = _tw()
    e = tw.energy(tw.times * 1.1, {})
    assert e["E_T"] == pytest.approx((0.1 * T) ** 2)
    assert e["E_V"] == pytest.approx(N * (0.1 * T / N) ** 2)
    assert e["E_S"] == pytest.approx(0.0, abs=1e-20)  # evenly: no speed change, at the seam neither


@pytest.mark.parametrize(
    ("key", "e_v", "e_s"),
    [
        (4, 2.0, 6.0),  # inside: gaps +d and -d; speed changes d, -2d, d
        (0, 1.0, 2.0),  # the first keypoint alone (its copy N not moved): the seam term sees it
        (N, 1.0, 2.0),  # the seam keypoint alone: the periodic term at i = 0 and the last inner one
    ],
)
def test_one_keypoint_bumped(key: int, e_v: float, e_s: float) -> None:
    tw, d = _tw(), 0.01
    t = tw.times.copy()
    t[key] += d
    e = tw.energy(t, {})
    assert e["E_V"] == pytest.approx(e_v * d**2) and e["E_S"] == pytest.approx(e_s * d**2)
    assert e["E_T"] == pytest.approx((0.0 if key not in (0, N) else d) ** 2, rel=1e-9, abs=1e-20)


def test_nothing_is_reported_before_the_first_solve() -> None:
    tw = _tw()
    assert tw.last_iterations == 0 and tw.last_status == ""
    tw.solve({3: 0.35})
    assert tw.last_iterations >= 1 and tw.last_status == "solved"


@pytest.mark.parametrize("key", [0, 3, N - 1])
def test_a_keypoint_asked_for_its_own_time_changes_nothing(key: int) -> None:
    tw = _tw()
    np.testing.assert_allclose(tw.solve({key: tw.times[key]}), tw.times, atol=1e-9)


def test_the_first_keypoint_drags_its_copy_at_the_seam() -> None:
    """Keypoint 0 asked to show 0.03 s: the seam (keypoint N) shows 0.03 s one period later."""
    t = _tw().solve({0: 0.03})
    assert t[0] == pytest.approx(0.03, abs=1e-6) and t[N] == pytest.approx(T + 0.03, abs=1e-6)
    np.testing.assert_allclose(np.diff(t), T / N, atol=1e-6)  # a pure shift


@pytest.mark.parametrize("key", [1, N - 1])
def test_one_drag_elsewhere_is_a_pure_shift_and_the_seam_follows(key: int) -> None:
    """One keypoint dragged 0.02 s: every energy but E_C is zero for a shift, so the warp is one."""
    t = _tw().solve({key: key * T / N + 0.02})
    np.testing.assert_allclose(t, _tw().times + 0.02, atol=1e-6)


def test_a_qp_that_does_not_finish_is_refused_with_its_status() -> None:
    """The active set needs several iterations when the drag asks for time to run backwards."""
    with pytest.raises(TimeWarpError, match="time-warp QP not solved: iteration limit"):
        TimeWarp(30, 1.0, max_iter=1).solve({10: 10 / 30, 12: 4 / 30})


def test_the_minimum_gap_holds() -> None:
    """Keypoint 6 asked to show keypoint 2's time: without a minimum the gaps before it close to 0."""
    tw = _tw()
    assert np.diff(tw.solve({3: 0.3, 6: 0.2})).min() < 1e-6
    assert np.diff(tw.solve({3: 0.3, 6: 0.2}, min_gap=0.02)).min() >= 0.02 - 1e-9


def test_three_keypoints_are_enough_and_two_are_not() -> None:
    assert TimeWarp(3, 1.0).solve({1: 0.4})[1] == pytest.approx(0.4, abs=1e-3)
    with pytest.raises(TimeWarpError, match="a cycle needs at least 3 keypoints to warp, got 2"):
        TimeWarp(2, 1.0)


@pytest.mark.parametrize("period", [0.0, -1.0, float("inf"), float("nan")])
def test_the_period_must_be_positive_and_finite(period: float) -> None:
    with pytest.raises(TimeWarpError, match="period must be positive and finite, got"):
        TimeWarp(N, period)


def test_the_refusals_name_the_keypoint() -> None:
    tw = _tw()
    with pytest.raises(TimeWarpError, match="keypoint 10 is outside 0…9"):
        tw.solve({10: 0.5})
    with pytest.raises(TimeWarpError, match="keypoint -1 is outside 0…9"):
        tw.solve({-1: 0.5})
    with pytest.raises(TimeWarpError, match="keypoint 3: wanted time inf is not finite"):
        tw.solve({3: float("inf")})
