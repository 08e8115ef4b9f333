"""Segments of a long take: each activity of a mixed take found, with its bounds and period."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from authoring.cycles.extract import CycleError, CycleResult, extract_cycle
from authoring.cycles.formats import load_performance
from authoring.cycles.segments import best_segment, cut, find_segments, looping_segments
from authoring.cycles.synthetic import loop_error, make_performance, mixed_take
from authoring.cycles.trajectory import TrajectoryError


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_three_activities_give_three_segments_at_their_bounds(seed: int) -> None:
    take, parts, bounds = mixed_take(12, np.random.default_rng(seed))
    with pytest.raises(CycleError):  # the premise: the whole take is refused
        extract_cycle(take)
    found = looping_segments(take)
    assert len(found) == 3
    for (seg, result), part, t0, t1 in zip(found, parts, bounds[:-1], bounds[1:], strict=True):
        assert abs(seg.t0 - t0) < 0.5 and abs(seg.t1 - t1) < 0.5, (seg, t0, t1)
        assert isinstance(result, CycleResult)
        assert result.period == pytest.approx(part.period, rel=0.03)
        assert loop_error(result.loop, part.truth)[0] < 0.1


def test_one_activity_is_one_segment_over_the_take() -> None:
    perf = make_performance(8, np.random.default_rng(5), cycles=8, period=0.9)
    segs = find_segments(perf.trajectory)
    assert len(segs) == 1
    assert segs[0].t0 < 0.2 and segs[0].t1 > perf.trajectory.times[-1] - 0.2
    assert segs[0].period == pytest.approx(0.9, rel=0.1)


def test_no_repetition_no_segment() -> None:
    from authoring.cycles.trajectory import Trajectory

    walk = np.cumsum(np.random.default_rng(3).normal(size=(900, 4)), axis=0)
    assert find_segments(Trajectory.uniform(walk, 60.0)) == []


def test_best_segment_is_none_when_nothing_loops_and_a_loop_otherwise() -> None:
    from authoring.cycles.segments import Segment

    seg = Segment(0, 10, 0.0, 1.0, 0.5, 0.1)
    assert best_segment([(seg, CycleError("no"))]) is None
    take, _, _ = mixed_take(12, np.random.default_rng(0))
    found = looping_segments(take)
    picked = best_segment(found)
    assert picked is not None and isinstance(picked[1], CycleResult)
    looped = [r for _, r in found if isinstance(r, CycleResult)]
    tightest = min(round(r.spread, 2) for r in looped)  # spreads within 1 % tie: then the most cycles
    assert round(picked[1].spread, 2) == tightest
    assert picked[1].cycles == max(r.cycles for r in looped if round(r.spread, 2) == tightest)


def test_cut_refuses_empty_and_outside() -> None:
    take, _, _ = mixed_take(3, np.random.default_rng(0))
    with pytest.raises(TrajectoryError):
        cut(take, 10, 10)
    with pytest.raises(TrajectoryError):
        cut(take, 0, take.num_samples + 1)
    part = cut(take, 100, 200)
    assert part.num_samples == 100 and part.times[0] == 0.0


def test_real_mocap_walk_is_one_segment_and_the_jump_none(mocap_dir: Path) -> None:
    walk = load_performance(mocap_dir / "cmu_16_15_walk_daz.bvh").trajectory
    ((seg, result),) = looping_segments(walk)
    assert isinstance(result, CycleResult) and result.period == pytest.approx(1.17, rel=0.03)
    assert seg.t1 - seg.t0 > 0.9 * walk.times[-1]
    jump = load_performance(mocap_dir / "cmu_13_32_forward_jump_NEGATIVE_daz.bvh").trajectory
    assert find_segments(jump) == []


@pytest.mark.fuzz
def test_fuzz_parse_bound() -> None:
    from hypothesis import given, settings
    from hypothesis import strategies as st

    from authoring.cycles.take_range import parse_bound

    @settings(max_examples=300, deadline=None)
    @given(st.text(max_size=12))
    def check(text: str) -> None:
        try:
            b = parse_bound(text)
        except ValueError:
            return
        assert b.unit in ("s", "f") and np.isfinite(b.value) and b.value >= 0

    check()
    assert parse_bound("480f").value == 480 and parse_bound("4.5s").value == 4.5 and parse_bound("2").unit == "s"
