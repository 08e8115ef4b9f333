"""Segments of a long take that loop: where each activity starts and ends, and its period.

The extractor (:mod:`.extract`) expects one activity repeated; a take of jumping jacks,
then twists, then squats is refused as a whole ("cycles too different", or no consistent
period). This module finds the parts that loop, so each can be extracted alone
(``cycle --start/--end``, and every segment of a take in ``puppetphone cycles``).

How: the weighted performance is resampled evenly (at most ~40 samples per second) and
reduced to its main components (PCA); a travelling root counts by its velocity, not its
position, because a walk never returns to where it was. For every start frame ``i`` and
lag ``L`` the *repeat score* is the mean squared distance between the cycle that starts
at ``i`` and the one after it, over the spread of those two cycles::

    S(i, L) = mean_j ‖x_j − x_{j+L}‖² / (2 · var(x_i … x_{i+2L}))     j ∈ [i, i+L)

``S`` is near 0 where the motion repeats with period ``L`` and near 1 where it does not.
Each frame's period is the shortest lag whose score is close to its best (so a double
period is not taken for the period); frames that repeat with nearly the same period
form a run, and a run becomes a segment covering the cycles its frames start. Every
segment found here is a *candidate*: the extractor still decides whether it loops.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from authoring.cycles.average import sample_linear
from authoring.cycles.extract import CycleError, CycleOptions, CycleResult, extract_cycle
from authoring.cycles.trajectory import Trajectory, TrajectoryError

__all__ = ["Segment", "SegmentSettings", "best_segment", "cut", "find_segments", "looping_segments"]

from engine.arrays import F64


@dataclass(frozen=True)
class SegmentSettings:
    """Knobs of the segment search.

    Attributes:
        min_period: shortest period considered, seconds.
        max_period: longest period considered, seconds.
        loop_score: a frame repeats when its best score is under this (0 = identical cycles).
        tolerance: a score within ``tolerance`` (absolute) + 25 % of the best counts as
            as good, so the shortest such lag is the period, not a multiple of it.
        same_period: neighbouring frames belong to one run while their periods agree within this share.
        min_cycles: a segment must span at least this many periods.
        components: principal components kept.
        max_rate: analysis samples per second at most (the search does not need 120 fps).
    """

    min_period: float = 0.25
    max_period: float = 4.0
    loop_score: float = 0.35
    tolerance: float = 0.03
    same_period: float = 0.25
    min_cycles: float = 2.5
    components: int = 16
    max_rate: float = 40.0


@dataclass(frozen=True)
class Segment:
    """A part of a take that repeats: samples ``[start, stop)`` of the trajectory.

    Attributes:
        start: first sample.
        stop: one past the last sample.
        t0: time of the first sample, seconds.
        t1: time of the sample after the last (or the last time plus one step), seconds.
        period: the period the search saw, seconds (the extractor refines it).
        score: median repeat score of the run (lower loops better).
    """

    start: int
    stop: int
    t0: float
    t1: float
    period: float
    score: float

    @property
    def cycles(self) -> float:
        """Periods the segment spans."""
        return (self.t1 - self.t0) / self.period


def _features(traj: Trajectory, step: float, components: int) -> tuple[F64, F64]:
    """Even times and ``[T', d]`` principal components of the weighted take (travel as velocity)."""
    t = np.arange(traj.times[0], traj.times[-1] + 1e-9, step)
    v = traj.values * traj.weights()
    for it in traj.items:
        if it.kind == "position" and it.travel:
            # Velocity times one second: metres of travel per second, on the position's scale.
            v[:, it.columns] = np.gradient(v[:, it.columns], traj.times, axis=0)
    x = sample_linear(traj.times, v, t)
    x = x - x.mean(axis=0)
    if x.shape[1] > components:
        vt = np.linalg.svd(x, full_matrices=False)[2]
        x = x @ vt[:components].T
    return t, x


def _scores(x: F64, lags: range) -> F64:
    """``S[i, k]`` for lag ``lags[k]`` (``inf`` where the two cycles do not fit in the take)."""
    n = len(x)
    out = np.full((n, len(lags)), np.inf)
    sq = np.einsum("ij,ij->i", x, x)
    csum_sq = np.concatenate([[0.0], np.cumsum(sq)])
    csum_x = np.concatenate([np.zeros((1, x.shape[1])), np.cumsum(x, axis=0)])
    for k, lag in enumerate(lags):
        m = n - 2 * lag + 1  # starts whose two cycles fit
        if m <= 0:
            break
        e = np.einsum("ij,ij->i", x[:-lag] - x[lag:], x[:-lag] - x[lag:])
        ce = np.concatenate([[0.0], np.cumsum(e)])
        i = np.arange(m)
        near = (ce[i + lag] - ce[i]) / lag
        w = 2 * lag
        mean = (csum_x[i + w] - csum_x[i]) / w
        var = (csum_sq[i + w] - csum_sq[i]) / w - np.einsum("ij,ij->i", mean, mean)
        out[:m, k] = near / np.maximum(2.0 * var, 1e-18)
    return out


def _frame_periods(s: F64, lags: range, cfg: SegmentSettings) -> tuple[NDArray[np.int64], F64]:
    """Each start frame's period (lag, 0 where it does not repeat) and its score."""
    best = s.min(axis=1)
    ok = np.isfinite(best) & (best < cfg.loop_score)
    # Local minima along the lag axis only: a score near its best on the slope of the
    # dip at the true period is not a shorter period.
    interior = np.full(s.shape, False)
    interior[:, 1:-1] = (s[:, 1:-1] <= s[:, :-2]) & (s[:, 1:-1] <= s[:, 2:])
    good = interior & (s <= best[:, None] * 1.25 + cfg.tolerance)
    first = np.argmax(good, axis=1)
    has = good.any(axis=1) & ok
    lag = np.where(has, np.asarray(lags)[first], 0)
    return lag.astype(np.int64), np.where(has, s[np.arange(len(s)), first], np.inf)


def _runs(lag: NDArray[np.int64], cfg: SegmentSettings) -> Iterator[tuple[int, int, float]]:
    """Maximal runs of start frames with agreeing periods: ``(first, last, median lag)``."""
    i, n = 0, len(lag)
    while i < n:
        if lag[i] == 0:
            i += 1
            continue
        j, members = i, [lag[i]]
        while j + 1 < n:
            ref = float(np.median(members))
            # A short dropout (a quarter period) inside a run does not end it.
            k = j + 1
            gap_limit = j + max(1, int(0.25 * ref))
            while k < n and lag[k] == 0 and k <= gap_limit:
                k += 1
            if k >= n or lag[k] == 0:
                break
            # A frame that sees two or three cycles as one (its shortest good lag a multiple) stays.
            m = max(1, round(lag[k] / ref))
            if m > 3 or abs(lag[k] / m - ref) > cfg.same_period * ref:
                break
            members.append(lag[k] // m)
            j = k
        yield i, j, float(np.median(members))
        i = j + 1


def find_segments(traj: Trajectory, settings: SegmentSettings | None = None) -> list[Segment]:
    """Candidate looping segments of a take, in time order, not overlapping.

    A take that is one activity throughout gives one segment covering (nearly) all of it;
    a take with no repetition gives none.
    """
    cfg = settings or SegmentSettings()
    if traj.num_samples < 3:  # nothing repeats in a frame or two (and their velocities are not defined)
        return []
    dt = traj.dt
    step = dt * max(1, int(np.floor(1.0 / (cfg.max_rate * dt))))
    t, x = _features(traj, step, cfg.components)
    lo = max(2, round(cfg.min_period / step))
    hi = min(round(cfg.max_period / step), (len(t) - 1) // 2)
    if hi <= lo + 2:
        return []
    lags = range(lo, hi + 1)
    s = _scores(x, lags)
    lag, score = _frame_periods(s, lags, cfg)
    raw: list[tuple[int, int, float, float]] = []
    last_start = -1
    for first, last, period in _runs(lag, cfg):
        begin, end = first, min(len(t) - 1, last + round(2 * period))
        run_scores = score[first : last + 1]
        entry = (begin, end, period, float(np.median(run_scores[np.isfinite(run_scores)])))
        # A dropout of under half a period between two runs of one period split one activity.
        if raw and first - last_start <= 0.5 * period and abs(raw[-1][2] - period) <= cfg.same_period * period:
            a = raw[-1]
            raw[-1] = (a[0], max(a[1], end), 0.5 * (a[2] + period), max(a[3], entry[3]))
        else:
            raw.append(entry)
        last_start = last
    raw = [r for r in raw if r[1] - r[0] >= cfg.min_cycles * r[2]]
    # Neighbours overlap by up to two periods (a run's frames look two cycles ahead): split the overlap.
    for k in range(1, len(raw)):
        a, b = raw[k - 1], raw[k]
        if b[0] < a[1]:
            mid = (b[0] + a[1]) // 2
            raw[k - 1] = (a[0], mid, a[2], a[3])
            raw[k] = (mid, b[1], b[2], b[3])
    out = []
    for begin, end, period, sc in raw:
        if end - begin < cfg.min_cycles * period:
            continue
        t0, t1 = float(t[begin]), float(t[end])
        start = int(np.searchsorted(traj.times, t0 - 1e-9))
        stop = min(traj.num_samples, int(np.searchsorted(traj.times, t1 + 1e-9, side="right")))
        end_time = float(traj.times[stop]) if stop < traj.num_samples else float(traj.times[-1] + dt)
        out.append(Segment(start, stop, float(traj.times[start]), end_time, period * step, sc))
    return out


def cut(traj: Trajectory, start: int, stop: int) -> Trajectory:
    """Samples ``[start, stop)`` of ``traj``, times shifted to start at 0.

    Raises:
        TrajectoryError: an empty or out-of-range cut.
    """
    n = traj.num_samples
    if not 0 <= start < stop <= n:
        raise TrajectoryError(f"the cut {start}–{stop} is not inside the take's {n} samples")
    if stop - start < 3:
        raise TrajectoryError(f"the cut {start}–{stop} holds {stop - start} samples; a cycle needs more")
    return Trajectory(traj.times[start:stop] - traj.times[start], traj.values[start:stop], traj.items)


def looping_segments(
    traj: Trajectory, options: CycleOptions | None = None, settings: SegmentSettings | None = None, seed: int = 0
) -> list[tuple[Segment, CycleResult | CycleError]]:
    """Every candidate segment with what the extractor made of it (a loop, or the refusal)."""
    out: list[tuple[Segment, CycleResult | CycleError]] = []
    for seg in find_segments(traj, settings):
        try:
            out.append((seg, extract_cycle(cut(traj, seg.start, seg.stop), np.random.default_rng(seed), options)))
        except (CycleError, TrajectoryError) as exc:
            out.append((seg, CycleError(str(exc))))
    return out


def best_segment(found: list[tuple[Segment, CycleResult | CycleError]]) -> tuple[Segment, CycleResult] | None:
    """The segment that loops best: the tightest aligned cycles, then the most of them."""
    looped = [(s, r) for s, r in found if isinstance(r, CycleResult)]
    if not looped:
        return None
    return min(looped, key=lambda sr: (round(sr[1].spread, 2), -sr[1].cycles))
