"""Cycle extraction, end to end (paper §4): performance in, one closed loop out, or a reason.

    descriptor → period (ten seeded probe points, median) → cut at the anchor's matches
    → correspondences and time alignment → average → stitch → spline fit

When the probes' vote fails or its cycles align poorly, the whole pose's autocorrelation
peak (:mod:`authoring.cycles.autocorr`) is tried as the period before anything is refused,
and wins when its cycles spread less than half as much: a short take of a real walk can
lead most probes to a third of its stride.

The paper's stated limitation is that a performance whose cycles differ too much in
shape or timing gives no period or a poor loop. Both are detected and reported as a
:class:`CycleError` whose message says which and why — the extractor never returns a
loop it does not believe in:

* *no period*: fewer than three of the ten probe points find a period at all, or fewer
  than three agree on it within 10 % (a single jump gives scattered "periods");
* *too few cycles*: fewer than two whole cycles lie between the anchor's matches;
* *cycles too different*: after alignment, the cycles' spread around their average
  exceeds ``max_spread`` times the average's own variation (weighted so positions and
  rotations count alike).
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from authoring.cycles.autocorr import pose_period
from authoring.cycles.average import AlignedCycles, average_cycles
from authoring.cycles.cutting import Cut, best_cut, consensus, try_multiples
from authoring.cycles.descriptor import K_DEFAULT, Descriptor
from authoring.cycles.period import PeriodSearch, PointPeriod, match_chain, search_periods
from authoring.cycles.spline import BezierLoop, fit_item
from authoring.cycles.stitch import closure_error, stitch
from authoring.cycles.trajectory import Trajectory

__all__ = ["CycleError", "CycleOptions", "CycleResult", "extract_cycle"]


class CycleError(ValueError):
    """No trustworthy cycle in a performance; the message gives the reason."""


@dataclass(frozen=True)
class CycleOptions:
    """Knobs of the extractor; the defaults are the paper's where it gives one.

    Attributes:
        k: descriptor window half-width (paper: 5).
        probes: number of random probe points (paper: 10).
        min_agreeing: probe points that must find a period, and agree on it.
        agreement: how close (share of the median) a probe's period must be to count as agreeing.
        min_cycles: whole cycles needed (one cycle can only be closed, not averaged).
        max_spread: refuse when aligned cycles spread more than this share of the loop's variation.
        good_spread: below this spread the first anchor's cut is kept; above it up to
            ``anchors`` candidate anchors are tried and the tightest alignment wins.
        anchors: how many anchors to try at most.
        samples: samples of the output loop (default: the period at the input's median rate).
        fit: also fit Bézier loops per item.
        fit_tolerance: spline error bound (share of range; radians for rotations); None = defaults.
        search: the period search settings.
    """

    k: int = K_DEFAULT
    probes: int = 10
    min_agreeing: int = 3
    agreement: float = 0.1
    min_cycles: int = 2
    max_spread: float = 0.75
    good_spread: float = 0.2
    anchors: int = 3
    samples: int | None = None
    fit: bool = True
    fit_tolerance: float | None = None
    search: PeriodSearch = field(default_factory=PeriodSearch)


@dataclass(frozen=True)
class CycleResult:
    """An extracted loop and how it was found.

    Attributes:
        period: seconds.
        period_samples: the period in samples of the input's median rate.
        loop: ``[S, N]`` the closed loop at ``loop_times`` (the end, equal to the start, left out).
        loop_times: ``[S]`` seconds, ``s · period / S``.
        travel: ``[N]`` per-cycle travel kept on travelling positions (zero elsewhere).
        closure_error: mismatch between the loop's end and its start (plus travel) after stitching.
        gap: ``‖d_ex‖`` per item before stitching (how open the average was).
        spread: the aligned cycles' spread relative to the loop's variation.
        aligned: the aligned cycles (for plots and diagnostics).
        average: ``[S+1, N]`` the average before stitching.
        points: the probe points' outcomes.
        anchor: the probe point whose matches cut the performance.
        curves: Bézier loops per item name (empty when ``fit`` was off). The root position's
            goes into a ``.ppclip`` for MoCurves to edit (:mod:`authoring.cycles.root_curve`);
            the rotation curves are kept for other callers (``cycle --json`` counts them, ~10 ms on
            a 43-joint walk) but no clip stores them: MoCurves edit rotations with per-keypoint
            arrows and have no rotation control points to start from.
    """

    period: float
    period_samples: float
    loop: NDArray[np.float64]
    loop_times: NDArray[np.float64]
    travel: NDArray[np.float64]
    closure_error: float
    gap: dict[str, float]
    spread: float
    aligned: AlignedCycles
    average: NDArray[np.float64]
    points: tuple[PointPeriod, ...]
    anchor: PointPeriod
    curves: dict[str, BezierLoop]

    @property
    def cycles(self) -> int:
        """How many performed cycles were averaged."""
        return self.aligned.count

    def closed(self) -> NDArray[np.float64]:
        """``[S+1, N]`` the loop with its end appended (start plus travel)."""
        return np.concatenate([self.loop, (self.loop[0] + self.travel)[None]], axis=0)


def _probe_points(n: int, count: int, k: int, rng: np.random.Generator) -> NDArray[np.int64]:
    lo, hi = min(k, n // 4), max(n - k, 3 * n // 4)
    pool = np.arange(lo, hi)
    return np.sort(rng.choice(pool, size=min(count, len(pool)), replace=False)).astype(np.int64)


def _travel(traj: Trajectory, aligned: AlignedCycles) -> NDArray[np.float64]:
    """Per-cycle travel of travelling columns where it is consistent (mean beyond 3 standard errors)."""
    travel = np.zeros(traj.dims)
    p = aligned.count
    for it in traj.items:
        if it.kind == "position" and it.travel:
            d = aligned.values[:, -1, it.columns]  # each cycle starts at 0 for these columns
            mean = d.mean(axis=0)
            sem = d.std(axis=0, ddof=1) / np.sqrt(p) if p > 1 else np.full_like(mean, np.inf)
            travel[it.columns] = np.where(np.abs(mean) > 3.0 * sem, mean, 0.0)
    return travel


def _pose_cut(
    traj: Trajectory,
    desc: Descriptor,
    values: NDArray[np.float64],
    weights: NDArray[np.float64],
    points: NDArray[np.int64],
    opt: CycleOptions,
    vote: float | None,
) -> Cut | None:
    """The cut at the whole pose's autocorrelation period (:mod:`authoring.cycles.autocorr`), when it differs from the vote.

    The chains are walked at that period from the probe points and from the earliest
    point the descriptor allows (a short take's whole cycles start near its beginning).
    ``None`` when the pose does not repeat strongly, agrees with the vote, or its cycles
    cannot be cut or spread beyond ``max_spread``.
    """
    n, dt = traj.num_samples, traj.dt
    found_lag = pose_period(traj, values, opt.search.min_period, n // 2)
    if found_lag is None or (vote is not None and abs(found_lag[0] * dt - vote) <= opt.agreement * vote):
        return None
    starts = np.unique(np.concatenate([points, [min(opt.k, n - 1)]])).astype(np.int64)
    rows = desc.rows(starts)
    found = [match_chain(traj.times, rows[a], int(starts[a]), found_lag[0], opt.search) for a in range(len(starts))]
    found = [f for f in found if f.period > 0 and len(f.matches) >= 2]
    if not found:
        return None
    agree, period = consensus(found, opt.agreement)
    cut, _ = best_cut(
        traj,
        desc,
        agree,
        period,
        opt.samples or max(8, round(period / dt)),
        weights,
        opt.search,
        opt.anchors,
        opt.min_cycles,
        opt.good_spread,
    )
    return cut if cut is not None and cut.spread <= opt.max_spread else None


def extract_cycle(
    traj: Trajectory,
    rng: np.random.Generator | None = None,
    options: CycleOptions | None = None,
    progress: Callable[[str, float], None] | None = None,
) -> CycleResult:
    """Extract one closed loop from a performance of several nearly equal cycles.

    Args:
        traj: the performance.
        rng: source of the random probe points (the world's generator inside the engine);
            a fixed seed when omitted, so results are reproducible.
        options: extractor settings.
        progress: called with (stage, fraction done) as the stages finish, for a progress bar.

    Raises:
        CycleError: no period, or cycles too different to average (the message says which).
    """
    opt = options or CycleOptions()
    rng = rng if rng is not None else np.random.default_rng(0)
    report = progress or (lambda stage, done: None)
    with _single_threaded_blas():
        return _extract(traj, rng, opt, report)


def _single_threaded_blas() -> contextlib.AbstractContextManager[object]:
    """One BLAS thread: the products here are small, and on a shared machine a multi-threaded
    BLAS spins against other processes (ten times slower measured); it also keeps the
    floating-point reduction order, hence the result, independent of the thread count."""
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:  # optional: without it BLAS keeps its own default
        return contextlib.nullcontext()
    return threadpool_limits(limits=1, user_api="blas")


def _extract(
    traj: Trajectory, rng: np.random.Generator, opt: CycleOptions, report: Callable[[str, float], None]
) -> CycleResult:
    n = traj.num_samples
    if n < 2 * opt.search.min_period + 1:
        raise CycleError(f"no period found: {n} samples are too few for two cycles of at least {opt.search.min_period}")
    weights = traj.weights()
    values = traj.values * weights
    if float(np.max(np.ptp(values, axis=0))) <= 1e-12:
        raise CycleError("no period found: the performance does not move")
    report("descriptor", 0.0)
    desc = Descriptor(traj.times, values, opt.k)
    points = _probe_points(n, opt.probes, opt.k, rng)
    rows = desc.rows(points)
    report("period", 0.35)
    per = search_periods(traj.times, rows, points, opt.search)
    found = [
        match_chain(traj.times, rows[a], int(points[a]), int(per[a]), opt.search)
        for a in range(len(points))
        if per[a] > 0
    ]
    found = [f for f in found if f.period > 0 and len(f.matches) >= 2]
    dt = traj.dt
    settings = (opt.search, opt.anchors, opt.min_cycles, opt.good_spread)

    def second_opinion(reason: str) -> Cut:
        """The cut at the whole pose's autocorrelation period, or the refusal."""
        cut = _pose_cut(traj, desc, values, weights, points, opt, None)
        if cut is None:
            raise CycleError(reason)
        return cut

    agree, period = consensus(found, opt.agreement) if found else ([], 0.0)
    if len(found) < min(opt.min_agreeing, len(points)):
        cut = second_opinion(
            f"no period found: only {len(found)} of {len(points)} probe points found a repeating match "
            "(the motion may not repeat, or its repetitions differ too much in shape or timing)"
        )
    elif len(agree) < min(opt.min_agreeing, len(points)):
        found_s = ", ".join(f"{f.period:.3g}" for f in found)
        cut = second_opinion(
            f"no consistent period: the probe points disagree (periods {found_s} s; fewer than "
            f"{opt.min_agreeing} within {opt.agreement:.0%} of the median); the motion does not repeat regularly"
        )
    else:
        report("alignment", 0.5)
        voted, most = best_cut(traj, desc, agree, period, opt.samples or max(8, round(period / dt)), weights, *settings)
        if voted is not None and voted.spread > opt.good_spread and opt.samples is None:
            voted = try_multiples(traj, desc, rows, points, voted, weights, opt.search, opt.agreement, *settings[1:])
        if voted is None or voted.spread > opt.good_spread:  # a poor alignment: is it the wrong period?
            alt = _pose_cut(traj, desc, values, weights, points, opt, period)
            voted = alt if alt is not None and (voted is None or alt.spread < 0.5 * voted.spread) else voted
        if voted is None:
            raise CycleError(
                f"too few cycles: a period of {period:.3g} s was found but only {most} whole cycle(s) could be cut "
                f"(at least {opt.min_cycles} are needed to average); perform more loops"
            )
        cut = voted
    period, anchor, aligned, spread = cut.period, cut.anchor, cut.aligned, cut.spread
    samples = len(aligned.phases) - 1
    report("average", 0.8)
    if not spread <= opt.max_spread:
        raise CycleError(
            f"cycles too different: after alignment the {aligned.count} cycles spread {spread:.0%} of the loop's own "
            f"variation (limit {opt.max_spread:.0%}); perform the loops more alike in shape and timing"
        )
    travel = _travel(traj, aligned)
    average = average_cycles(traj, aligned)
    closed, d_ex = stitch(traj, average, aligned.phases, travel)
    gaps = {it.name: float(np.linalg.norm(d_ex[it.columns])) for it in traj.items}
    loop = closed[:-1]
    loop_times = np.arange(samples, dtype=np.float64) * (period / samples)
    curves: dict[str, BezierLoop] = {}
    report("spline fit", 0.9)
    if opt.fit:
        for it in traj.items:
            block = loop[:, it.columns]
            if it.kind == "position" and it.travel:
                # Fit the in-place part; the travel is a straight ramp added back by the caller.
                block = block - np.outer(np.arange(samples) / samples, travel[it.columns])
            curves[it.name] = fit_item(it, block, period, opt.fit_tolerance)
    report("done", 1.0)
    return CycleResult(
        period=period,
        period_samples=period / dt,
        loop=loop,
        loop_times=loop_times,
        travel=travel,
        closure_error=closure_error(traj, closed, travel),
        gap=gaps,
        spread=spread,
        aligned=aligned,
        average=average,
        points=cut.points,
        anchor=anchor,
        curves=curves,
    )
