"""A part of a take, in the file's own frames or seconds: ``cycle --start/--end`` and the refusal hint.

People read positions off the file they have: a frame number in a BVH viewer, a time in
a CSV. The trajectory the extractor sees may have dropped leading frames (the T-pose of
CMU conversions: :attr:`Performance.skipped`), so positions are converted here, in one
place, both ways: a :class:`Bound` (``4.0`` or ``4.0s`` seconds, ``480f`` a frame) into
trajectory samples, and a found segment back into the file's frames and seconds for
the hint printed when a whole take is refused.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from authoring.cycles.extract import CycleError, extract_cycle
from authoring.cycles.formats import Performance, load_performance, performance_from_motion, save_loop
from authoring.cycles.periodic_part import leg_joints, steps_part
from authoring.cycles.segments import Segment, best_segment, cut, looping_segments
from authoring.cycles.trajectory import TrajectoryError

__all__ = ["Bound", "cycle_of_take", "parse_bound", "refusal_hint", "select"]


@dataclass(frozen=True)
class Bound:
    """A position in a take: ``value`` seconds (``unit = "s"``) or frame ``value`` (``unit = "f"``)."""

    value: float
    unit: str

    def __str__(self) -> str:
        return f"{int(self.value)}f" if self.unit == "f" else f"{self.value:g}s"


def parse_bound(text: str) -> Bound:
    """``"4.0"`` or ``"4.0s"`` → seconds, ``"480f"`` → frame 480 (counted from 0 in the file).

    Raises:
        ValueError: anything else, or a negative position.
    """
    t = text.strip().lower()
    unit = "f" if t.endswith("f") else "s"
    number = t[:-1] if t.endswith(("f", "s")) else t
    try:
        value = float(number) if unit == "s" else float(int(number))
    except ValueError:
        raise ValueError(f"{text!r} is not a time in seconds (4.0, 4.0s) or a frame number (480f)") from None
    if not np.isfinite(value) or value < 0:
        raise ValueError(f"{text!r}: a position in the take is a time or frame from 0 on")
    return Bound(value, unit)


def _file_times(perf: Performance) -> np.ndarray:
    """Each trajectory sample's time in the file (leading skipped frames put back)."""
    return perf.trajectory.times + perf.skipped * perf.trajectory.dt


def _sample(perf: Performance, bound: Bound) -> int:
    """The trajectory sample at ``bound``; past the take's end (one step of slack) gives ``n + 1``."""
    if bound.unit == "f":
        return int(bound.value) - perf.skipped
    times = _file_times(perf)
    if bound.value > times[-1] + 1.5 * perf.trajectory.dt:
        return len(times) + 1
    return int(np.searchsorted(times, bound.value - 1e-9))


def select(perf: Performance, start: Bound | None, end: Bound | None) -> tuple[Performance, int]:
    """The performance cut to ``[start, end)``, and the first kept sample's index in the trajectory.

    Raises:
        TrajectoryError: the range is empty, reversed, outside the take, or too short.
    """
    traj = perf.trajectory
    n = traj.num_samples
    first = 0 if start is None else _sample(perf, start)
    stop = n if end is None else _sample(perf, end)
    times = _file_times(perf)
    span = f"frames {perf.skipped}–{perf.skipped + n - 1}, {times[0]:.3f}–{times[-1]:.3f} s"
    if first < 0 or first >= n or stop > n or stop <= first:
        raise TrajectoryError(f"--start {start or 0} --end {end or 'the end'} is not a range inside the take ({span})")
    return dataclasses.replace(perf, trajectory=cut(traj, first, stop)), first


def _describe(perf: Performance, seg: Segment, offset: int, period: float, cycles: int) -> str:
    times = _file_times(perf)
    f0, f1 = seg.start + offset + perf.skipped, seg.stop - 1 + offset + perf.skipped
    t0 = float(times[seg.start + offset])
    t1 = float(times[seg.stop + offset]) if seg.stop + offset < len(times) else float(times[-1] + perf.trajectory.dt)
    return (
        f"frames {f0}–{f1} loop with period {period:.2f} s ({cycles} cycles); "
        f"try --start {round(t0, 2):g} --end {round(t1, 2):g}"
    )


def refusal_hint(perf: Performance, analysed: Performance, offset: int = 0, seed: int = 0) -> str | None:
    """When a take was refused: the best-looping part of ``analysed`` as a ``--start/--end`` to try.

    ``analysed`` is ``perf`` or a part of it starting at trajectory sample ``offset``. The
    segments whose whole pose repeats come first; when there are none (a dance that turns
    and varies its arms), the part where the feet repeat (:mod:`.periodic_part`) is offered
    if the extractor loops it, whole or by the legs alone (then with ``--items``). ``None``
    when no part loops either way.
    """
    best = best_segment(looping_segments(analysed.trajectory, seed=seed))
    if best is not None:
        seg, result = best
        return _describe(perf, seg, offset, result.period, result.cycles)
    return _steps_hint(perf, analysed, offset, seed)


def _steps_hint(perf: Performance, analysed: Performance, offset: int, seed: int) -> str | None:
    """The ``--start/--end`` (and ``--items``, for the legs alone) of the part where the feet repeat, if it loops."""
    part = steps_part(analysed, offset)
    legs = leg_joints(analysed)
    if part is None or legs is None or perf.motion is None:
        return None
    seg = Segment(part.start, part.stop, 0.0, 0.0, part.period, 1.0 - part.correlation)
    whole_legs = performance_from_motion(perf.motion, list(legs))
    for items, source in ((None, analysed.trajectory), (legs, whole_legs.trajectory)):
        first = part.start + (offset if items else 0)
        try:
            result = extract_cycle(cut(source, first, first + part.stop - part.start), np.random.default_rng(seed))
        except (CycleError, TrajectoryError):
            continue
        said = _describe(perf, seg, offset, result.period, result.cycles)
        if items is None:
            return f"the steps repeat there: {said}"
        return (
            f"the whole pose varies, but the steps repeat: {said.replace(' loop ', ' loop by the legs ')} "
            f"--items {' '.join(items)}"
        )
    return None


def cycle_of_take(take: Path, start: Bound | None, end: Bound | None, out: Path, seed: int = 0) -> Path:
    """Extract the loop of ``take`` between ``start`` and ``end`` and write it to ``out`` (``author edit`` opens it).

    Raises:
        ValueError: an unreadable take, a range outside it, or no loop there (with the hint of the part that loops).
    """
    whole = load_performance(take)
    perf, offset = select(whole, start, end)
    try:
        result = extract_cycle(perf.trajectory, np.random.default_rng(seed))
    except CycleError as exc:
        hint = refusal_hint(whole, perf, offset, seed)
        raise ValueError(f"{exc}" + (f"; {hint}" if hint else "")) from None
    return save_loop(result, perf, out)
