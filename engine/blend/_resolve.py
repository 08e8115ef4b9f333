"""The changed requests of one locomotion set resolved in a few calls: standing heights, scaling, inside test, IDW.

:func:`engine.blend._requests.resolve` hands the rows whose request changed since last step
to :func:`resolve_rows`. Its numpy path is :meth:`LocomotionSet.standing_heights` (a
``height=None`` request stands as tall as the set can at that speed) then
:meth:`LookupTable.resolve_many`: some forty numpy calls whatever the number of rows, a
fixed cost that dominated the animation stage of a hundred puppets. With numba the same
formulas run as one compiled pass (:func:`_prepare`: standing heights, the requests in
the table's units, their finiteness), one k-d tree query for the simplices near each
request, the compiled inside test, and one k-d tree query and the compiled IDW for the
answers; only a request outside the feasible set is projected on its own in Python, as
before. Each operation is the one :func:`stepwise` runs with numba, in its order, so both give the
same bits (``tests/engine/blend/test_resolve.py``); without numba :func:`stepwise` is the path.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from engine import jit
from engine.arrays import F64 as F
from engine.arrays import Bool
from engine.blend.feasible import _contains_compiled, line_range_row
from engine.blend.lookup import LookupTable

if TYPE_CHECKING:
    from engine.blend.locomotion import LocomotionSet

__all__ = ["resolve_rows", "stepwise"]

_TOLERANCE = 1e-6  # FeasibleSet.contains_many's default
_LIMITS: dict[int, tuple[LookupTable, float, float, float]] = {}


def resolve_rows(loco: LocomotionSet, speeds: F, heights: F, standing: Bool) -> tuple[F, F, Bool, F]:
    """Blend points, feasible requests, inside flags and rates for requests ``(speeds, heights)`` in the set's
    units (``heights`` is ignored where ``standing``): what :meth:`LookupTable.resolve_many` answers."""
    table = loco.table
    fs = table.feasible
    if not jit.enabled() or fs is None or table.values.shape[1] != 2:
        return stepwise(loco, speeds, heights, standing)
    _, fastest, floor, tallest = _limits(table)
    count = len(speeds)
    u, x = np.empty((count, 2)), np.empty((count, 2))
    inv, ok = fs._line[1]
    if not _prepare(speeds, heights, standing, table.offset, table.scale, fastest, floor, tallest, inv, ok, u, x):
        raise ValueError("request contains NaN or infinite values")
    _, near = fs._centroids.query(x, k=min(12, len(fs.simplices)))
    inside = np.empty(count, dtype=np.bool_)
    _contains_compiled(fs.values, fs.simplices, fs._inv, fs._valid, near.reshape(count, -1), x, _TOLERANCE, inside)
    rates = np.ones(count)
    for i in np.flatnonzero(~inside):  # outside the feasible set: projected one by one (the unusual request)
        res = table.resolve(u[i])
        u[i], inside[i], rates[i] = res.feasible, res.inside, res.rate
        x[i] = table._scaled(u[i])
    return table.query_scaled(x), u, inside, rates


def stepwise(loco: LocomotionSet, speeds: F, heights: F, standing: Bool) -> tuple[F, F, Bool, F]:
    """:func:`resolve_rows` as the set's methods compute it (the numpy path, and with numba the reference
    that the fused pass matches bit for bit: those methods then run the same compiled inside test and IDW)."""
    h = heights.copy()
    if standing.any():
        h[standing] = loco.standing_heights(speeds[standing])
    return loco.table.resolve_many(np.stack([speeds, h], axis=-1))


def _limits(table: LookupTable) -> tuple[LookupTable, float, float, float]:
    """The table's fastest speed, first probe's height and tallest height (what standing heights read)."""
    hit = _LIMITS.get(id(table))
    if hit is None or hit[0] is not table:
        values = table.values
        hit = _LIMITS[id(table)] = (table, float(values[:, 0].max()), float(values[0, 1]), float(values[:, 1].max()))
    return hit


@jit.njit
def _prepare(
    speeds: F,
    heights: F,
    standing: NDArray[np.bool_],
    offset: F,
    scale: F,
    fastest: float,
    floor: float,
    tallest: float,
    inv: F,
    ok: NDArray[np.bool_],
    u: F,
    x: F,
) -> bool:
    """Each row's request ``u`` (a standing row's height: the highest border crossing at its speed, capped at
    ``fastest``, from the height ``floor``; ``tallest`` where none) and ``x``, it in the table's units;
    ``False`` at the first value that is not finite there."""
    point = np.empty(2)
    for r in range(speeds.shape[0]):
        s, h = speeds[r], heights[r]
        if standing[r]:
            point[0] = (min(s, fastest) - offset[0]) / scale[0]
            point[1] = (floor - offset[1]) / scale[1]
            if not (math.isfinite(point[0]) and math.isfinite(point[1])):
                return False
            h = line_range_row(inv, ok, point, 1)[1] * scale[1] + offset[1]
            if math.isnan(h):
                h = tallest
        u[r, 0], u[r, 1] = s, h
        x[r, 0] = (s - offset[0]) / scale[0]
        x[r, 1] = (h - offset[1]) / scale[1]
        if not (math.isfinite(x[r, 0]) and math.isfinite(x[r, 1])):
            return False
    return True
