"""From the probes' periods to the cut: consensus, the anchor, and a check against sub-periods.

* **Consensus** — the median period of the largest group of probes that agree within
  ``agreement`` (a plain median is pulled off by probes that locked onto a sub-pattern).
* **The cut** — candidate anchors (agreeing with the consensus, most repetitions first,
  cleanest matches next) cut the performance into cycles, which are aligned; the
  alignment whose cycles spread least around their average wins.
* **Sub-periods** — the paper takes the *smallest* period whose repetitions all match.
  A curve that nearly repeats within its cycle (a one-dimensional curve dominated by its
  second harmonic) can pass at ``T/2``, ``T/3`` or ``2T/3``; its "cycles" then alternate
  between different halves and spread widely. When the best spread is poor, the chains
  are walked again at 1.5, 2 and 3 times the period; among the multiples whose (at least
  three) cycles spread less than half as much, the shortest that aligns well wins.

The spread is the RMS deviation of the aligned cycles from their average, over the
RMS variation of the average, with positions and rotations weighted alike and each
cycle's own offset (drift) removed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from authoring.cycles.average import AlignedCycles, align_cycles
from authoring.cycles.descriptor import Descriptor
from authoring.cycles.period import PeriodSearch, PointPeriod, match_chain
from authoring.cycles.trajectory import Trajectory
from engine import quat

__all__ = ["Cut", "best_cut", "consensus", "spread", "try_multiples"]

MULTIPLES = (1.5, 2.0, 3.0)


@dataclass(frozen=True)
class Cut:
    """The chosen cut: its period (s), the anchor, the aligned cycles and their spread."""

    period: float
    anchor: PointPeriod
    aligned: AlignedCycles
    spread: float
    points: tuple[PointPeriod, ...]


def consensus(found: list[PointPeriod], agreement: float) -> tuple[list[PointPeriod], float]:
    """The largest group of mutually agreeing probes and its median period."""
    periods = np.array([f.period for f in found])
    support = [np.abs(periods - p) <= agreement * p for p in periods]
    best = max(range(len(found)), key=lambda a: (int(support[a].sum()), -abs(periods[a] - np.median(periods))))
    agree = [f for f, ok in zip(found, support[best], strict=True) if ok]
    return agree, float(np.median([f.period for f in agree]))


def spread(traj: Trajectory, aligned: AlignedCycles, weights: NDArray[np.float64]) -> float:
    """How much the aligned cycles differ from their average, relative to the average's own variation."""
    vals = aligned.values.copy()
    for it in traj.rotation_items():
        ref = vals[len(vals) // 2][None, :, it.columns]
        vals[:, :, it.columns] = quat.align_hemisphere(vals[:, :, it.columns], ref)
    vals *= weights
    vals -= vals.mean(axis=1, keepdims=True)
    mean = vals.mean(axis=0)
    dev = float(np.sqrt(np.mean((vals - mean) ** 2)))
    sig = float(np.sqrt(np.mean((mean - mean.mean(axis=0)) ** 2)))
    return dev / sig if sig > 0 else float("inf")


def best_cut(
    traj: Trajectory,
    desc: Descriptor,
    agree: list[PointPeriod],
    period: float,
    samples: int,
    weights: NDArray[np.float64],
    search: PeriodSearch,
    anchors: int,
    min_cycles: int,
    good_spread: float,
) -> tuple[Cut | None, int]:
    """The tightest alignment among up to ``anchors`` candidates; also the most whole cycles any could cut."""
    ranked = sorted(agree, key=lambda f: (abs(f.period - period) > 0.03 * period, -len(f.matches), f.score))
    best: Cut | None = None
    most = 0
    for anchor in ranked[:anchors]:
        consecutive = np.flatnonzero(np.diff(anchor.repetition) == 1)
        cuts = np.stack([anchor.matches[consecutive], anchor.matches[consecutive + 1]], axis=1)
        most = max(most, len(cuts))
        if len(cuts) < min_cycles:
            continue
        aligned = align_cycles(traj, desc, cuts, samples, search.timing_tolerance)
        s = spread(traj, aligned, weights)
        if best is None or s < best.spread:
            best = Cut(period, anchor, aligned, s, tuple(agree))
        if s <= good_spread:  # clean enough: no need to try another anchor
            break
    return best, most


def try_multiples(
    traj: Trajectory,
    desc: Descriptor,
    rows: NDArray[np.float64],
    points: NDArray[np.int64],
    current: Cut,
    weights: NDArray[np.float64],
    search: PeriodSearch,
    agreement: float,
    anchors: int,
    min_cycles: int,
    good_spread: float,
) -> Cut:
    """Replace a poorly aligned cut by one at a multiple of its period when that aligns far better."""
    index = {int(p): a for a, p in enumerate(points)}
    dt = traj.dt
    options = []
    for factor in MULTIPLES:
        redone = [
            match_chain(traj.times, rows[index[f.index]], f.index, round(factor * f.period / dt), search)
            for f in current.points
        ]
        redone = [f for f in redone if f.period > 0 and len(f.matches) >= 2]
        if len(redone) < 2:
            continue
        agree, period = consensus(redone, agreement)
        cut, _ = best_cut(
            traj,
            desc,
            agree,
            period,
            max(8, round(period / dt)),
            weights,
            search,
            anchors,
            max(min_cycles, 3),
            good_spread,
        )
        if cut is not None and cut.spread < 0.5 * current.spread:
            options.append(cut)
    if not options:
        return current
    # The shortest period that aligns well; failing that, the tightest alignment.
    good = [c for c in options if c.spread <= good_spread]
    return min(good, key=lambda c: c.period) if good else min(options, key=lambda c: c.spread)
