"""Period evaluation (paper §4, "Period evaluation"): the most probable period of a performance.

For a point ``i``, ``J_i`` holds the local minima of ``d_D(i, ·)`` under a conservative
threshold ``d_D^m``; the period is the smallest ``T`` for which every repetition ``k`` has a
``j ∈ J_i`` within ``m_T = ⌈T/8⌉`` samples of where the ``k``-th repetition should be. Ten random
points (from the caller's seeded generator) each give a period; the median wins.

Three choices, made for robustness and written down here because they go beyond the
paper's text:

* **Outliers in J_i** are minima that are not real dips: local minima whose
  prominence is under a tenth of the threshold come from noise wiggles, and when the
  dips' depths fall into two distinct classes (a two-class split of their logarithms,
  classes a factor ``separation`` apart) the shallow class goes too. Those are what
  lets a far too short period pass the test by luck.
* **Where repetition k is expected** is predicted from the last *found* match
  (``t_last + T``), not from ``t_i + kT``: a performer's tempo drifts, and the absolute
  prediction accumulates every cycle's timing error. A repetition whose window would
  reach past either end of the recording is not asked for.
* **Misses.** A human cycle may be off by more than ``T/8`` (the issue asks for ±15 %
  jitter); one such cycle would otherwise forbid the true period and hand the win to
  twice the period. Up to a third of the repetitions may miss, never all of them.
  Half or a third of the true period still fails, since then every other repetition
  misses.

The search runs for all ten points and every candidate ``T`` at once, as arrays, and
stops following a candidate as soon as its miss budget is spent.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.signal import find_peaks

__all__ = ["PeriodSearch", "PointPeriod", "candidate_minima", "match_chain", "search_periods"]

MISS_FRACTION = 0.25
TIMING_TOLERANCE = 1.0 / 8.0


@dataclass(frozen=True)
class PeriodSearch:
    """Settings of the period search.

    Attributes:
        threshold_quantile: ``d_D^m`` as this quantile of the row (high = conservative).
        prominence: minimum dip depth as a fraction of ``d_D^m`` (outlier removal).
        separation: factor between the deep and shallow dips beyond which the shallow are outliers.
        timing_tolerance: ``m_T = ⌈T · timing_tolerance⌉`` samples (paper: 1/8).
        miss_fraction: share of repetitions allowed to find no match.
        min_period: shortest period considered, in samples.
        max_fraction: longest period considered as a share of the recording (two cycles
            at least are needed to average anything).
    """

    threshold_quantile: float = 0.5
    prominence: float = 0.1
    timing_tolerance: float = TIMING_TOLERANCE
    miss_fraction: float = MISS_FRACTION
    min_period: int = 8
    max_fraction: float = 0.6
    separation: float = 4.0


@dataclass(frozen=True)
class PointPeriod:
    """The outcome for one probe point ``i``.

    Attributes:
        index: the point ``i``.
        period_samples: the integer period found (0 when none).
        matches: sorted indices of the cleaned ``J_i`` (one per matched repetition, ``i`` included).
        repetition: the repetition number ``k`` of each match (``0`` for ``i``).
        period: refined period in seconds: the mean duration between the first and last match.
        score: mean ``d_D`` of the matches (lower is a cleaner point).
    """

    index: int
    period_samples: int
    matches: NDArray[np.int64]
    repetition: NDArray[np.int64]
    period: float
    score: float


def candidate_minima(row: NDArray[np.float64], search: PeriodSearch, index: int | None = None) -> NDArray[np.int64]:
    """``J_i``: local minima of one ``d_D`` row under the threshold, outliers removed.

    ``index`` is the point ``i`` itself: always kept, and left out when telling deep
    dips from shallow ones (its ``d_D`` is zero by definition and says nothing).
    """
    thr = float(np.quantile(row, search.threshold_quantile))
    if thr <= 0.0:
        return np.zeros(0, dtype=np.int64)
    wall = float(row.max()) + 1.0
    padded = np.concatenate([[wall], row, [wall]])  # so the two ends can be minima
    peaks, _ = find_peaks(-padded, height=-thr, prominence=search.prominence * thr)
    minima = (peaks - 1).astype(np.int64)
    others = minima != index
    keep = np.ones(len(minima), dtype=bool)
    keep[others] = _inliers(row[minima[others]], search.separation)
    return minima[keep]


def _inliers(values: NDArray[np.float64], separation: float) -> NDArray[np.bool_]:
    """Keep the deep class of dips: a two-class split (Otsu) of the log depths, if the classes are distinct.

    True repetitions of a point are far more similar to it than the other dips under a
    conservative threshold (typically ten times); when the log depths fall into two
    classes whose means differ by more than ``separation`` (a factor), the shallow class
    is the outliers. A single class is kept whole.
    """
    keep = np.ones(len(values), dtype=bool)
    if len(values) < 3 or not values.max() > 0:
        return keep
    # Exact matches (d_D = 0, the point itself or noise-free repeats) are the deepest dips.
    logs = np.log(np.maximum(values, 1e-12 * values.max()))
    x = np.sort(logs)
    n = len(x)
    csum = np.cumsum(x)
    k = np.arange(1, n)
    m0 = csum[:-1] / k
    m1 = (csum[-1] - csum[:-1]) / (n - k)
    between = k * (n - k) * (m1 - m0) ** 2
    best = int(np.argmax(between))
    if m1[best] - m0[best] < np.log(separation):
        return keep
    cut = 0.5 * (x[best] + x[best + 1])
    return logs <= cut


def _flat_sets(
    times: NDArray[np.float64], sets: list[NDArray[np.int64]]
) -> tuple[NDArray[np.float64], NDArray[np.int64], float]:
    """All ``J_i`` in one sorted array: row ``p`` is shifted by ``p · stride`` so one searchsorted serves all."""
    span = float(times[-1] - times[0])
    stride = 4.0 * span + 1.0
    flat = np.concatenate([times[s] + p * stride for p, s in enumerate(sets)])
    idx = np.concatenate(sets)
    return flat, idx, stride


def search_periods(
    times: NDArray[np.float64], rows: NDArray[np.float64], points: NDArray[np.int64], search: PeriodSearch
) -> NDArray[np.int64]:
    """The minimal passing integer period (samples) for each probe point; 0 where none passes."""
    n = len(times)
    dt = float(np.median(np.diff(times)))
    t0, t1 = float(times[0]), float(times[-1])
    t_max = max(search.min_period, math.ceil(search.max_fraction * (n - 1)))
    cands = np.arange(search.min_period, t_max + 1, dtype=np.int64)
    sets = [candidate_minima(r, search, int(i)) for r, i in zip(rows, points, strict=True)]
    if len(cands) == 0 or not any(len(s) for s in sets):
        return np.zeros(len(points), dtype=np.int64)
    flat, _, stride = _flat_sets(times, sets)
    P, C = len(points), len(cands)
    per = np.broadcast_to(cands * dt, (P, C)).ravel()
    tol = np.broadcast_to(np.ceil(cands * search.timing_tolerance) * dt, (P, C)).ravel()
    anchor = np.repeat(times[points], C)
    offset = np.repeat(np.arange(P) * stride, C)
    # Expected number of repetitions inside the recording, hence each candidate's miss budget.
    expected = np.floor((t1 - anchor - tol) / per) + np.floor((anchor - t0 - tol) / per)
    budget = np.floor(search.miss_fraction * np.maximum(expected, 0))
    misses = np.zeros(P * C)
    hits = np.zeros(P * C)
    for direction in (1.0, -1.0):
        last = anchor.copy()
        gap = np.ones(P * C)
        alive = np.ones(P * C, dtype=bool)
        while True:
            target = last + direction * gap * per
            inside = (target + tol <= t1 + 1e-9) & (target - tol >= t0 - 1e-9)
            alive &= inside & (misses <= budget)
            act = np.flatnonzero(alive)
            if len(act) == 0:
                break
            q = target[act] + offset[act]
            pos = np.searchsorted(flat, q)
            lo = flat[np.clip(pos - 1, 0, len(flat) - 1)]
            hi = flat[np.clip(pos, 0, len(flat) - 1)]
            near = np.minimum(np.abs(q - lo), np.abs(q - hi))
            hit = near < tol[act] - 1e-9
            late = ~hit & (near < 2.0 * tol[act] - 1e-9)
            # Move the prediction onto the match found, which absorbs tempo drift; a match
            # just outside the window is a miss but still where the next cycle starts.
            moved = hit | late
            found = np.where(np.abs(q - lo) <= np.abs(q - hi), lo, hi)[moved] - offset[act[moved]]
            last[act[moved]] = found
            gap[act[moved]] = 1.0
            hits[act[hit]] += 1
            gap[act[~moved]] += 1.0
            misses[act[~hit]] += 1
    ok = (hits >= 1) & (misses <= budget)
    ok = ok.reshape(P, C)
    first = np.argmax(ok, axis=1)
    return np.where(ok.any(axis=1), cands[first], 0).astype(np.int64)


def match_chain(
    times: NDArray[np.float64],
    row: NDArray[np.float64],
    index: int,
    period_samples: int,
    search: PeriodSearch,
    iterations: int = 4,
) -> PointPeriod:
    """Clean ``J_i`` for a found period: one match per repetition, then refine the period.

    Walks forwards and backwards from ``i`` as the search did, but picks, among the
    candidate minima inside ``±m_T`` of the prediction, the one with the lowest ``d_D``.
    The search returns the *smallest* passing integer period, which sits at the low edge
    of what the ``±T/8`` windows allow; a chain walked with it can lose a long final
    cycle. So the chain is walked again with its own measured period (mean duration
    between first and last match) until that stops changing.
    """
    dt = float(np.median(np.diff(times)))
    cand = candidate_minima(row, search, index)
    per = period_samples * dt
    best = _chain(times, row, cand, index, per, period_samples, search)
    for _ in range(iterations):
        if best.period <= 0 or abs(best.period - per) < 0.05 * dt:
            break
        per = best.period
        again = _chain(times, row, cand, index, per, period_samples, search)
        if len(again.matches) < len(best.matches):
            break
        best = again
    return best


def _chain(
    times: NDArray[np.float64],
    row: NDArray[np.float64],
    cand: NDArray[np.int64],
    index: int,
    per: float,
    period_samples: int,
    search: PeriodSearch,
) -> PointPeriod:
    """One walk of the chain with period ``per`` seconds."""
    dt = float(np.median(np.diff(times)))
    tol = math.ceil(per / dt * search.timing_tolerance) * dt
    ct = times[cand]
    t0, t1 = float(times[0]), float(times[-1])
    matches = [index]
    reps = [0]
    for direction in (1, -1):
        last, k, gap = float(times[index]), 0, 1
        while True:
            target = last + direction * gap * per
            if target + tol > t1 + 1e-9 or target - tol < t0 - 1e-9:
                break
            k_here = k + direction * gap
            sel = np.flatnonzero(np.abs(ct - target) < tol - 1e-9)
            if len(sel) == 0:
                sel = np.flatnonzero(np.abs(ct - target) < 2.0 * tol - 1e-9)  # a late or early cycle
            if len(sel):
                best = cand[sel[np.argmin(row[cand[sel]])]]
                matches.append(int(best))
                reps.append(k_here)
                last, k, gap = float(times[best]), k_here, 1
            else:
                gap += 1
    order = np.argsort(reps)
    m = np.asarray(matches, dtype=np.int64)[order]
    r = np.asarray(reps, dtype=np.int64)[order]
    keep = np.concatenate([[True], np.diff(m) > 0])  # never the same sample twice
    m, r = m[keep], r[keep]
    refined = float((times[m[-1]] - times[m[0]]) / (r[-1] - r[0])) if len(m) > 1 and r[-1] != r[0] else 0.0
    others = m[m != index]
    score = float(np.mean(row[others])) if len(others) else float("inf")
    return PointPeriod(index, period_samples, m, r, refined, score)
