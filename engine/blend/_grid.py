"""Compiled searches over a lookup table's points in the plane, on a uniform grid of cells.

A crowd's lookup asks two questions of SciPy's ``cKDTree`` per request: which simplex
centroids are near (the inside test's first guesses) and which ``k`` probes are nearest
(the IDW's neighbours). Each costs microseconds per request, most of the animation stage's
lookup for a hundred puppets, although the tables are small (a thousand probes in two
properties). Here both run in numba over a grid of cells made once per table:

- :func:`knn`: the ``k`` nearest points by rings of cells around the request, stopped when
  no cell left can hold a nearer point. Distances are ``cKDTree``'s (``√(dx² + dy²)``, in
  that order), so where the ``k + 1`` nearest have distinct distances its neighbours, their
  order and their distances are the tree's, bit for bit. A row with a tie among them (the
  tree's order is then its own) is flagged, and its caller asks the tree.
- :class:`BoxGrid`: for each cell, the boxes (simplices' bounds) that touch it: the first
  guesses of an inside test that falls back to every simplex when none holds the point, so
  its answer does not depend on the guesses.

Only two-dimensional points are gridded (:func:`grid_of` returns ``None`` otherwise).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from engine.arrays import F64 as F
from engine.arrays import I64 as Ix
from engine.jit import njit, njit_inline

__all__ = ["BoxGrid", "PointGrid", "box_grid", "cell_of", "grid_of", "knn", "knn_row"]

_PER_CELL = 2.0  # points per cell aimed at: a request's k nearest lie within two or three rings
_MARGIN = 1e-9  # a ring's clearance is shrunk by this (scaled units) before it can stop the search


@dataclass(frozen=True)
class PointGrid:
    """Points ``[P, 2]`` sorted into cells: cell ``(i, j)`` (flat ``i·shape[1] + j``) holds
    ``items[start[c]:start[c + 1]]``; the grid spans ``lo + [0, shape)·size``."""

    points: F
    lo: F
    size: F
    shape: Ix
    start: Ix
    items: Ix


@dataclass(frozen=True)
class BoxGrid:
    """Boxes ``[lo, hi]`` sorted into the cells of a grid they touch (``start``/``items`` as :class:`PointGrid`)."""

    lo: F
    size: F
    shape: Ix
    start: Ix
    items: Ix


def _cells(lo: F, hi: F, count: int) -> tuple[F, Ix]:
    """Cell size and shape of a grid over ``[lo, hi]`` with about ``count / _PER_CELL`` cells."""
    side = max(1, math.ceil(math.sqrt(count / _PER_CELL)))
    span = np.maximum(hi - lo, 1e-12)
    return span / side, np.array([side, side], dtype=np.int64)


def _sorted(cell_of: list[list[int]]) -> tuple[Ix, Ix]:
    """CSR arrays of per-cell item lists."""
    start = np.zeros(len(cell_of) + 1, dtype=np.int64)
    start[1:] = np.cumsum([len(c) for c in cell_of])
    items = np.array([i for c in cell_of for i in c], dtype=np.int64)
    return start, items


def grid_of(points: F) -> PointGrid | None:
    """The grid of ``points [P, 2]`` (``None`` for points of another dimension)."""
    pts = np.ascontiguousarray(points, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1] != 2 or not len(pts):
        return None
    lo = pts.min(axis=0)
    size, shape = _cells(lo, pts.max(axis=0), len(pts))
    cell = np.minimum(np.floor((pts - lo) / size).astype(np.int64), shape - 1)
    cell_of: list[list[int]] = [[] for _ in range(int(shape[0] * shape[1]))]
    for i, (a, b) in enumerate(cell.tolist()):
        cell_of[a * int(shape[1]) + b].append(i)
    start, items = _sorted(cell_of)
    return PointGrid(pts, lo, size, shape, start, items)


def box_grid(lo_boxes: F, hi_boxes: F, margin: float) -> BoxGrid:
    """The grid of boxes ``[B, 2]`` (each grown by ``margin``) over their bounds, each box in every cell it touches."""
    lo_b, hi_b = lo_boxes - margin, hi_boxes + margin
    lo = lo_b.min(axis=0)
    size, shape = _cells(lo, hi_b.max(axis=0), len(lo_b))
    first = np.clip(np.floor((lo_b - lo) / size).astype(np.int64), 0, shape - 1)
    last = np.clip(np.floor((hi_b - lo) / size).astype(np.int64), 0, shape - 1)
    cell_of: list[list[int]] = [[] for _ in range(int(shape[0] * shape[1]))]
    for b, (f, t) in enumerate(zip(first.tolist(), last.tolist(), strict=True)):
        for i in range(f[0], t[0] + 1):
            for j in range(f[1], t[1] + 1):
                cell_of[i * int(shape[1]) + j].append(b)
    start, items = _sorted(cell_of)
    return BoxGrid(lo, size, shape, start, items)


@njit
def cell_of(lo: F, size: F, shape: Ix, x0: float, x1: float) -> int:
    """The flat cell holding ``(x0, x1)``, ``-1`` outside the grid (or not finite)."""
    a = (x0 - lo[0]) / size[0]
    b = (x1 - lo[1]) / size[1]
    if not (a >= 0.0 and b >= 0.0):
        return -1
    i, j = math.floor(a), math.floor(b)
    if i >= shape[0] or j >= shape[1]:
        return -1
    return i * shape[1] + j


@njit
def knn(
    points: F, lo: F, size: F, shape: Ix, start: Ix, items: Ix, x: F, k: int, dist: F, idx: Ix, exact: np.ndarray
) -> None:
    """:func:`knn_row` of every request ``x [Q, 2]``."""
    m = min(k + 1, points.shape[0])
    best_d, best_i = np.empty(m), np.empty(m, dtype=np.int64)
    for r in range(x.shape[0]):
        exact[r] = knn_row(points, lo, size, shape, start, items, x, r, k, best_d, best_i, dist, idx)


@njit_inline
def knn_row(
    points: F,
    lo: F,
    size: F,
    shape: Ix,
    start: Ix,
    items: Ix,
    x: F,
    r: int,
    k: int,
    best_d: F,
    best_i: Ix,
    dist: F,
    idx: Ix,
) -> bool:
    """The ``k`` nearest points of request ``x[r]``, nearest first, into ``dist[r]``/``idx[r]`` (``best_d``/``best_i``:
    scratch of ``min(k + 1, P)``); ``False`` where two of the ``k + 1`` nearest are equally far (then ``cKDTree``
    may order or pick them otherwise: ask it)."""
    m = best_d.shape[0]
    gx, gy = shape[0], shape[1]
    x0, x1 = x[r, 0], x[r, 1]
    cx = min(max(math.floor((x0 - lo[0]) / size[0]), 0), gx - 1)
    cy = min(max(math.floor((x1 - lo[1]) / size[1]), 0), gy - 1)
    found = 0
    ring = 0
    while True:
        for i in range(cx - ring, cx + ring + 1):
            if i < 0 or i >= gx:
                continue
            edge = i == cx - ring or i == cx + ring
            j = cy - ring
            while j <= cy + ring:
                if 0 <= j < gy:
                    c = i * gy + j
                    for s in range(start[c], start[c + 1]):
                        q = items[s]
                        d0 = x0 - points[q, 0]
                        d1 = x1 - points[q, 1]
                        d = d0 * d0 + d1 * d1
                        if found == m and not d < best_d[m - 1]:
                            continue
                        t = found if found < m else m - 1
                        while t > 0 and best_d[t - 1] > d:
                            best_d[t] = best_d[t - 1]
                            best_i[t] = best_i[t - 1]
                            t -= 1
                        best_d[t] = d
                        best_i[t] = q
                        if found < m:
                            found += 1
                j = j + 1 if edge or j == cy + ring else cy + ring
        if cx - ring <= 0 and cy - ring <= 0 and cx + ring >= gx - 1 and cy + ring >= gy - 1:
            break  # every cell seen
        if found == m:
            gap = math.inf  # how far the request is from any cell not seen yet
            if cx - ring > 0:
                gap = min(gap, x0 - (lo[0] + (cx - ring) * size[0]))
            if cx + ring < gx - 1:
                gap = min(gap, lo[0] + (cx + ring + 1) * size[0] - x0)
            if cy - ring > 0:
                gap = min(gap, x1 - (lo[1] + (cy - ring) * size[1]))
            if cy + ring < gy - 1:
                gap = min(gap, lo[1] + (cy + ring + 1) * size[1] - x1)
            gap -= _MARGIN
            if gap > 0.0 and gap * gap > best_d[m - 1]:
                break
        ring += 1
    tie = False
    for t in range(min(k, m - 1)):
        if best_d[t] == best_d[t + 1]:
            tie = True
    for t in range(k):
        dist[r, t] = math.sqrt(best_d[t])
        idx[r, t] = best_i[t]
    return not tie
