"""Where a long take repeats only in part: the steps of a dance under its turns and arm work.

A salsa take (CMU 60_04) is refused as a whole, and the segment search
(:mod:`.segments`) finds no part of it where the *whole pose* repeats: the dancer turns,
and the arms vary from one basic step to the next. The feet, though, keep the step's
rhythm, and for some seconds they keep it closely. This module finds those seconds, so
the refusal can say where to look (``--start/--end``) instead of saying nothing.

How: the heights of the two feet (world space, so turning does not matter) are the
signal. Their autocorrelation over the analysed part gives the step period (its strongest
peak between 0.25 and 4 s); a window of three periods is slid along the take, and at each
start the correlation of the window's first two periods with the two after one period
measures how closely the steps repeat there. The longest run of windows at or above
:data:`CLOSE` (0.7) is the periodic part. Like a segment it is a candidate: the caller
lets the extractor decide whether it loops (whole pose, or the legs alone).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.signal import find_peaks

from authoring.cycles.formats import Performance

__all__ = ["CLOSE", "StepsPart", "leg_joints", "steps_part"]

CLOSE = 0.7
"""Correlation of a window with itself one period later from which the steps repeat closely."""
_PERIODS = (0.25, 4.0)  # seconds: the step periods looked for
_RATE = 40.0  # samples per second at most (the step rhythm needs no more)
_WINDOW = 2  # periods compared at each start (the window spans one more)
_LEGS = ("hips", "l_upper_leg", "l_lower_leg", "l_foot", "r_upper_leg", "r_lower_leg", "r_foot")


@dataclass(frozen=True)
class StepsPart:
    """Samples ``[start, stop)`` of the analysed trajectory where the feet repeat with ``period`` seconds."""

    start: int
    stop: int
    period: float
    correlation: float


def leg_joints(perf: Performance) -> tuple[str, ...] | None:
    """The source's hips and leg joints (upper leg, lower leg, foot on each side), or ``None`` when no map finds them."""
    from engine.io.joint_maps import guess_joint_map

    if perf.clip is None:
        return None
    names = perf.clip.skeleton.names
    try:
        _, mapping, _ = guess_joint_map(names)
    except ValueError:
        return None
    if not all(mapping.get(role) in names for role in _LEGS):
        return None
    return tuple(mapping[role] for role in _LEGS)


def _foot_heights(perf: Performance, offset: int, count: int) -> NDArray[np.float64] | None:
    """``[count, 2]`` heights of the two feet over trajectory samples ``[offset, offset + count)``."""
    from engine.fk import forward_kinematics

    legs = leg_joints(perf)
    clip = perf.clip
    if legs is None or clip is None or offset + count > clip.num_frames:
        return None
    feet = [clip.skeleton.index(legs[3]), clip.skeleton.index(legs[6])]
    span = slice(offset, offset + count)
    translations = None if clip.translations is None else clip.translations[span]
    pos, _ = forward_kinematics(clip.skeleton, clip.root[span], clip.rotations[span], translations)
    return np.asarray(pos[:, feet, 1], dtype=np.float64)


def _correlation(a: NDArray[np.float64], b: NDArray[np.float64]) -> float:
    a = a - a.mean(axis=0)
    b = b - b.mean(axis=0)
    den = float(np.sqrt(np.sum(a * a) * np.sum(b * b)))
    return float(np.sum(a * b)) / den if den > 0 else 0.0


def _longest_run(flags: NDArray[np.bool_]) -> tuple[int, int] | None:
    """First and last index of the longest run of ``True``."""
    best: tuple[int, int] | None = None
    edges = np.flatnonzero(np.diff(np.concatenate([[0], flags.astype(np.int8), [0]])))
    for first, end in zip(edges[::2], edges[1::2], strict=True):
        if best is None or end - first > best[1] - best[0] + 1:
            best = (int(first), int(end) - 1)
    return best


def steps_part(perf: Performance, offset: int = 0) -> StepsPart | None:
    """The part of ``perf``'s trajectory (a part of the take from sample ``offset`` of its clip) where the feet repeat.

    ``None`` for input without a skeleton or legs, a take too short for three periods, or
    one whose steps repeat closely nowhere.
    """
    n = perf.trajectory.num_samples
    heights = _foot_heights(perf, offset, n)
    if heights is None:
        return None
    dt = perf.trajectory.dt
    step = max(1, int(np.floor(1.0 / (_RATE * dt))))
    x = heights[::step]
    lo = max(2, round(_PERIODS[0] / (dt * step)))
    hi = min(round(_PERIODS[1] / (dt * step)), len(x) // (_WINDOW + 1))
    if hi <= lo + 2 or np.ptp(x) <= 0:
        return None
    r = np.array([_correlation(x[:-lag], x[lag:]) for lag in range(lo, hi + 1)])
    peaks, _ = find_peaks(r)
    if not len(peaks):
        return None
    lag = lo + int(peaks[np.argmax(r[peaks])])
    width = _WINDOW * lag
    local = np.array(
        [_correlation(x[s : s + width], x[s + lag : s + lag + width]) for s in range(len(x) - width - lag + 1)]
    )
    run = _longest_run(local >= CLOSE)
    if run is None:
        return None
    first, last = run
    return StepsPart(
        first * step, min(n, (last + width + lag) * step), lag * step * dt, float(np.median(local[first : last + 1]))
    )
