"""A locomotion set's changed requests resolved in one compiled pass: scaling, standing heights, inside test, IDW.

:func:`engine.blend._requests.resolve` answers the rows whose request changed since last step.
The numpy path is :meth:`LocomotionSet.standing_heights` (a ``height=None`` request stands as
tall as the set can at that speed) then :meth:`LookupTable.resolve_many` (:func:`stepwise`):
some forty numpy calls whatever the number of rows, a fixed cost that dominated the animation
stage of a hundred puppets. With numba :func:`resolve_changed` does it all in one pass over the
batch: each request in the set's units, the test whether it changed, and for a changed row its
standing height, the inside test and the nearest probes on the table's grids of cells
(:mod:`engine.blend._grid`, no k-d tree query) and the IDW. Only a request outside the feasible
set is projected on its own in Python, as before. Each operation is the one :func:`stepwise`
runs with numba, in its order, row by row, so both give the same bits
(``tests/engine/blend/test_resolve.py``); without numba :func:`stepwise` is the path.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from engine import jit
from engine.arrays import F64 as F
from engine.arrays import Bool
from engine.blend._grid import knn_row
from engine.blend.feasible import contains_row, line_range_row
from engine.blend.lookup import _NO_SLOPES, LookupTable, idw_row

if TYPE_CHECKING:
    from engine.blend.locomotion import LocomotionSet

__all__ = ["resolve_changed", "resolve_rows", "stepwise"]

_TOLERANCE = 1e-6  # FeasibleSet.contains_many's default
_LIMITS: dict[int, tuple[LookupTable, float, float, float]] = {}


def resolve_rows(loco: LocomotionSet, speeds: F, heights: F, standing: Bool) -> tuple[F, F, Bool, F]:
    """Blend points, feasible requests, inside flags and rates for requests ``(speeds, heights)`` in the set's
    units (``heights`` is ignored where ``standing``): what :meth:`LookupTable.resolve_many` answers."""
    fused = resolve_changed(loco, speeds, heights, standing, np.ones(len(speeds)), None)
    if fused is None:
        return stepwise(loco, speeds, heights, standing)
    points, feasible, inside, rates = fused[3]
    return points, feasible, inside, rates


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


def resolve_changed(
    loco: LocomotionSet,
    speeds: F,
    heights: F,
    standing: Bool,
    scales: F,
    last: tuple[F, F, Bool, F, F, Bool, F] | None,
) -> tuple[int, F, F, tuple[F, F, Bool, F]] | None:
    """The compiled path of :func:`engine.blend._requests.resolve` in one pass over a batch's requests (player
    units): each row's request in the set's units, and where it differs from ``last`` (last step's requests in
    set units and answers; ``None``: every row) its answer as :func:`resolve_rows` gives it. Returns how many
    rows changed, the requests in set units and the answers (last step's where unchanged); ``None`` where this
    path does not apply (numba off, no border, not two properties, no grid): then the caller takes the other.

    A request outside the feasible set, or whose nearest probes tie (see :func:`engine.blend._grid.knn`), is
    finished here in Python, as :func:`resolve_rows` does."""
    table = loco.table
    fs, grid = table.feasible, table._grid
    if not jit.enabled() or fs is None or grid is None or fs._cells is None or table.values.shape[1] != 2:
        return None
    count = len(speeds)
    _, fastest, floor, tallest = _limits(table)
    line_inv, line_ok = fs._line[1]
    cells = fs._cells
    out_speeds, out_heights = np.empty(count), np.empty(count)
    if last is None:
        last_speeds, last_heights, last_standing = speeds, heights, standing  # not read: every row is resolved
        points, feasible = np.empty((count, table.probes.shape[1])), np.empty((count, 2))
        inside, rates = np.empty(count, dtype=np.bool_), np.empty(count)
    else:
        last_speeds, last_heights, last_standing = last[0], last[1], last[2]
        points, feasible, inside, rates = last[3].copy(), last[4].copy(), last[5].copy(), last[6].copy()
    k = min(table.neighbours, len(table.probes))
    status = np.zeros(count, dtype=np.int8)
    u, x = np.empty((count, 2)), np.empty((count, 2))
    changed = _resolve_compiled(
        speeds,
        heights,
        standing,
        scales,
        last_speeds,
        last_heights,
        last_standing,
        last is None,
        table.offset,
        table.scale,
        fastest,
        floor,
        tallest,
        line_inv,
        line_ok,
        fs.values,
        fs.simplices,
        fs._inv,
        fs._valid,
        cells.lo,
        cells.size,
        cells.shape,
        cells.start,
        cells.items,
        grid.points,
        grid.lo,
        grid.size,
        grid.shape,
        grid.start,
        grid.items,
        k,
        table.probes,
        table._scaled_values,
        _NO_SLOPES if table.slopes is None else table.slopes,
        table.slopes is not None,
        float(table.power),
        out_speeds,
        out_heights,
        u,
        x,
        status,
        points,
        feasible,
        inside,
        rates,
    )
    if changed < 0:
        raise ValueError("request contains NaN or infinite values")
    unusual = np.flatnonzero(status)
    if len(unusual):
        for i in unusual[status[unusual] == _OUTSIDE]:  # projected one by one (the unusual request)
            res = table.resolve(u[i])
            feasible[i], inside[i], rates[i] = res.feasible, res.inside, res.rate
            x[i] = table._scaled(feasible[i])
        points[unusual] = table.query_scaled(x[unusual])
    return changed, out_speeds, out_heights, (points, feasible, inside, rates)


_OUTSIDE, _TIED = 1, 2  # a row's status after the compiled pass: projected, or neighbours asked of the tree


@jit.njit
def _resolve_compiled(
    speeds: F,
    heights: F,
    standing: Bool,
    scales: F,
    last_speeds: F,
    last_heights: F,
    last_standing: Bool,
    every: bool,
    offset: F,
    scale: F,
    fastest: float,
    floor: float,
    tallest: float,
    line_inv: F,
    line_ok: NDArray[np.bool_],
    values: F,
    simplices: NDArray[np.int64],
    simplex_inv: F,
    valid: NDArray[np.bool_],
    cell_lo: F,
    cell_size: F,
    cell_shape: NDArray[np.int64],
    cell_start: NDArray[np.int64],
    cell_items: NDArray[np.int64],
    grid_points: F,
    grid_lo: F,
    grid_size: F,
    grid_shape: NDArray[np.int64],
    grid_start: NDArray[np.int64],
    grid_items: NDArray[np.int64],
    k: int,
    probes: F,
    scaled: F,
    slopes: F,
    use_slopes: bool,
    power: float,
    out_speeds: F,
    out_heights: F,
    u: F,
    x: F,
    status: NDArray[np.int8],
    points: F,
    feasible: F,
    inside: Bool,
    rates: F,
) -> int:
    """Each row's request in the set's units (``speed/scale``, ``height/scale`` or 0 standing) and, where it
    changed since last step (or ``every``), :func:`_prepare`'s request, the inside test
    (:func:`~engine.blend.feasible.contains_row`), the nearest probes (:func:`~engine.blend._grid.knn_row`) and
    the IDW (:func:`~engine.blend.lookup.idw_row`): the operations of :func:`resolve_rows`, row by row. Rows left
    to Python get a ``status``. Returns the number of changed rows, ``-1`` at a value that is not finite."""
    m = min(k + 1, grid_points.shape[0])
    best_d, best_i = np.empty(m), np.empty(m, dtype=np.int64)
    dist, idx = np.empty((speeds.shape[0], k)), np.empty((speeds.shape[0], k), dtype=np.int64)
    acc = np.empty(probes.shape[1])
    point = np.empty(2)
    changed = 0
    for r in range(speeds.shape[0]):
        s = speeds[r] / scales[r]
        h = 0.0 if standing[r] else heights[r] / scales[r]
        out_speeds[r], out_heights[r] = s, h
        if not every and s == last_speeds[r] and h == last_heights[r] and standing[r] == last_standing[r]:
            continue
        changed += 1
        if standing[r]:
            point[0] = (min(s, fastest) - offset[0]) / scale[0]
            point[1] = (floor - offset[1]) / scale[1]
            if not (math.isfinite(point[0]) and math.isfinite(point[1])):
                return -1
            h = line_range_row(line_inv, line_ok, point, 1)[1] * scale[1] + offset[1]
            if math.isnan(h):
                h = tallest
        u[r, 0], u[r, 1] = s, h
        x[r, 0] = (s - offset[0]) / scale[0]
        x[r, 1] = (h - offset[1]) / scale[1]
        if not (math.isfinite(x[r, 0]) and math.isfinite(x[r, 1])):
            return -1
        feasible[r, 0], feasible[r, 1] = s, h
        inside[r], rates[r] = True, 1.0
        if not contains_row(
            values,
            simplices,
            simplex_inv,
            valid,
            cell_lo,
            cell_size,
            cell_shape,
            cell_start,
            cell_items,
            x,
            r,
            _TOLERANCE,
        ):
            status[r] = _OUTSIDE
            continue
        if not knn_row(
            grid_points, grid_lo, grid_size, grid_shape, grid_start, grid_items, x, r, k, best_d, best_i, dist, idx
        ):
            status[r] = _TIED
            continue
        idw_row(x, r, dist, idx, probes, scaled, slopes, use_slopes, power, acc, points)
    return changed
