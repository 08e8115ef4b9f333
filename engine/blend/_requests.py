"""The animation stage's first step for one locomotion set's puppets: requests read, checked, resolved.

A step's requests are read from the players' row block (:mod:`engine.rows`), where the
state machine writes them, or one field at a time (a list comprehension each) from players
not in rows; they are checked as arrays (an invalid one is named by its entity, as before), and turned
into blend points by the set's lookup table (:meth:`LookupTable.resolve_many`).

The lookup is a pure function of a request in the set's units, so a row asking exactly
what it asked last step gets last step's answer (:class:`LastAnswers`): a puppet walking
straight on, or a crowd standing idle, costs one array comparison, and the rows that
changed (a few of a hundred wanderers turning, say) are resolved in one batch. This
replaces a memo keyed per request, whose per-puppet dictionary work cost more than the
lookup it saved; the answers are the same, bit for bit, whichever rows are resolved together
(``resolve_many`` treats rows independently).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from itertools import compress, count, repeat
from operator import is_, is_not
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from engine import jit
from engine.arrays import F64 as F
from engine.arrays import Bool
from engine.blend._resolve import resolve_changed, resolve_rows
from engine.ecs import Entity
from engine.rows import RowBlock

if TYPE_CHECKING:
    from engine.blend.locomotion import LocomotionPlayer, LocomotionSet

__all__ = ["Answers", "LastAnswers", "Requests", "read", "resolve"]


@dataclass(frozen=True)
class Requests:
    """A batch's requests as arrays, and the other player fields the stage reads with them.

    Attributes:
        speeds: requested ground speeds ``[P]`` (m/s, puppet units).
        heights: requested hips heights ``[P]`` (m), NaN where the puppet stands tall.
        standing: ``[P]`` where the height was ``None``.
        scales: each puppet's size relative to the set's clips ``[P]``.
        phases: the players' phases ``[P]``.
        overrides: each player's override clip name, or ``None``.
    """

    speeds: F
    heights: F
    standing: Bool
    scales: F
    phases: F
    overrides: list[str | None]

    def override_rows(self) -> list[int]:
        """The rows whose player plays a clip over its blend (the unusual puppets), found in one C-level pass."""
        return list(compress(count(), map(is_not, self.overrides, repeat(None))))


def read(
    entities: Sequence[Entity],
    players: Sequence[LocomotionPlayer],
    at: tuple[RowBlock, slice | NDArray[np.intp]] | None = None,
    scales: F | None = None,
) -> Requests:
    """The players' requests and fields; ``ValueError`` names the first entity with an invalid request
    (speed not finite or negative, height not finite) or scale (not finite or not positive). ``at``: the
    players' rows in their block (:mod:`engine.rows`), where their requests, phases and overrides are read whole;
    ``scales``: the players' scales, if the caller has them (read from the players otherwise).

    One list per field: a comprehension's attribute loads are the interpreter's cached fast path,
    cheaper per puppet than one ``attrgetter`` of every field and the transposition after it."""
    if scales is None:
        scales = np.array([p.scale for p in players], dtype=np.float64)
    if at is None:
        height = [p.height for p in players]
        speeds = np.array([p.speed for p in players], dtype=np.float64)
        standing = np.fromiter(map(is_, height, repeat(None)), dtype=np.bool_, count=len(height))
        heights = np.array(height, dtype=np.float64)  # None becomes NaN
        phases = np.array([p.phase for p in players], dtype=np.float64)
        override = [p.override for p in players]
    else:  # copies: the state machine writes the next requests there, and the stage the new phases
        arrays, rows = at[0].arrays, at[1]
        given = at[0].present["height"][rows]
        speeds = np.array(arrays["speed"][rows])
        standing = ~given
        heights = np.where(given, arrays["height"][rows], np.nan)
        phases = np.array(arrays["phase"][rows])
        override = arrays["override"][rows].tolist()
    i, request_bad = _first_invalid(speeds, heights, standing, scales)
    if i >= 0:
        bad = players[i]
        if request_bad:
            raise ValueError(
                f"entity {entities[i]}: locomotion request speed={bad.speed!r}, height={bad.height!r} is invalid"
            )
        raise ValueError(f"entity {entities[i]}: locomotion scale {bad.scale!r} must be positive")
    return Requests(speeds, heights, standing, scales, phases, override)


def _first_invalid(speeds: F, heights: F, standing: Bool, scales: F) -> tuple[int, bool]:
    """The first row with an invalid request or scale (``-1`` if none), and whether its request is the bad part."""
    return (
        _first_invalid_compiled(speeds, heights, standing, scales)
        if jit.enabled()
        else _first_invalid_numpy(speeds, heights, standing, scales)
    )


def _first_invalid_numpy(speeds: F, heights: F, standing: Bool, scales: F) -> tuple[int, bool]:
    good_request = np.isfinite(speeds) & (speeds >= 0.0) & (standing | np.isfinite(heights))
    bad = np.flatnonzero(~(good_request & np.isfinite(scales) & (scales > 0.0)))
    return (-1, False) if not len(bad) else (int(bad[0]), not good_request[bad[0]])


@jit.njit
def _first_invalid_compiled(speeds: F, heights: F, standing: Bool, scales: F) -> tuple[int, bool]:
    for i in range(speeds.shape[0]):
        s, h, k = speeds[i], heights[i], scales[i]
        request_ok = math.isfinite(s) and s >= 0.0 and (standing[i] or math.isfinite(h))
        if not (request_ok and math.isfinite(k) and k > 0.0):
            return i, not request_ok
    return -1, False


@dataclass(frozen=True)
class Answers:
    """The lookup's answers ``[P, …]``: blend points, feasible requests (set units), inside flags, rates."""

    points: F
    feasible: F
    inside: Bool
    rates: F


@dataclass(frozen=True)
class LastAnswers:
    """One set's requests (set units; standing rows hold 0 as height) and answers of the last step."""

    loco: LocomotionSet
    speeds: F
    heights: F
    standing: Bool
    answers: Answers


def resolve(last: dict[str, LastAnswers], key: str, loco: LocomotionSet, req: Requests) -> Answers:
    """The set's answers for a batch's requests; rows unchanged since ``last[key]`` are not resolved again."""
    before = last.get(key)
    if before is not None and (before.loco is not loco or len(before.speeds) != len(req.speeds)):
        before = None
    kept = None
    if before is not None:
        old = before.answers
        kept = (before.speeds, before.heights, before.standing, old.points, old.feasible, old.inside, old.rates)
    fused = resolve_changed(loco, req.speeds, req.heights, req.standing, req.scales, kept)
    if fused is not None:
        changed, speeds, heights, (points, feasible, inside, rates) = fused
        if before is not None and not changed:
            return before.answers
        answers = Answers(points, feasible, inside, rates)
        last[key] = LastAnswers(loco, speeds, heights, req.standing, answers)
        return answers
    speeds = req.speeds / req.scales
    heights = np.where(req.standing, 0.0, req.heights / req.scales)
    if before is None:
        todo = None
    else:
        changed_rows = (speeds != before.speeds) | (heights != before.heights) | (req.standing != before.standing)
        if not changed_rows.any():
            return before.answers
        todo = np.flatnonzero(changed_rows)
    if todo is None:
        points, feasible, inside, rates = resolve_rows(loco, speeds, heights, req.standing)
    else:
        points, feasible, inside, rates = resolve_rows(loco, speeds[todo], heights[todo], req.standing[todo])
    if todo is not None and before is not None:
        old = before.answers
        points, part = old.points.copy(), points
        points[todo] = part
        feasible, part = old.feasible.copy(), feasible
        feasible[todo] = part
        inside, part_inside = old.inside.copy(), inside
        inside[todo] = part_inside
        rates, part = old.rates.copy(), rates
        rates[todo] = part
    answers = Answers(points, feasible, inside, rates)
    last[key] = LastAnswers(loco, speeds, heights, req.standing, answers)
    return answers
