"""The feasible set of a lookup table: the image of the probe grid in user-property space.

Each probe of the grid over ``[0,1]^N`` has measured properties ``u`` (speed, crouch
height, …). The grid's cells, split into simplices (Kuhn/Freudenthal: ``N!`` per
cell, which tile the cube with no gaps and agree on shared faces), map to simplices
in ``u``-space; their union is the set of requests some blend can play. Its border
is the image of the grid's boundary facets — for ``N = 2`` a polygon, in higher
dimensions "a multi-dimensional mesh" (thesis §6.2.3). A request outside is
projected onto the nearest point of that mesh.

Everything is vectorised over simplices: a 21×21 grid has 800 triangles and 80
border segments, so the inside test and the projection are a few numpy calls.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial import cKDTree

from engine import jit

__all__ = ["FeasibleSet", "kuhn_simplices", "border_facets", "closest_point_on_simplices"]

from engine.arrays import F64 as F
from engine.arrays import I64 as Ix


def kuhn_simplices(shape: tuple[int, ...]) -> Ix:
    """Vertex indices ``[S, N+1]`` (into the C-ordered grid) of the Kuhn triangulation of a grid."""
    n = len(shape)
    cells = np.stack(np.meshgrid(*[np.arange(s - 1) for s in shape], indexing="ij"), axis=-1).reshape(-1, n)
    out = []
    for perm in itertools.permutations(range(n)):
        verts = [cells]
        cur = cells.copy()
        for d in perm:
            cur = cur.copy()
            cur[:, d] += 1
            verts.append(cur)
        idx = np.stack([np.ravel_multi_index(tuple(v.T), shape) for v in verts], axis=-1)
        out.append(idx)
    return np.concatenate(out, axis=0).astype(np.int64)


def border_facets(shape: tuple[int, ...], simplices: Ix) -> Ix:
    """Facets ``[B, N]`` of ``simplices`` that lie on the grid's boundary."""
    coords = np.stack(np.unravel_index(np.arange(int(np.prod(shape))), shape), axis=-1)
    n = len(shape)
    facets = []
    for drop in range(n + 1):
        f = np.delete(simplices, drop, axis=1)
        c = coords[f]  # [S, N, N]
        lo = np.all(c == 0, axis=1)
        hi = np.all(c == np.array(shape) - 1, axis=1)
        on = np.any(lo | hi, axis=-1)
        facets.append(f[on])
    allf = np.concatenate(facets, axis=0)
    return np.unique(np.sort(allf, axis=1), axis=0)


def closest_point_on_simplices(verts: ArrayLike, u: ArrayLike) -> tuple[F, F]:
    """Closest points ``[S, M]`` on each simplex ``verts [S, V, M]`` to ``u [M]``, and their distances ``[S]``.

    The closest point lies in the relative interior of some face, where the
    unconstrained projection onto that face's affine hull has positive barycentrics;
    so every face (``2^V − 1`` vertex subsets, 3 for a segment, 7 for a triangle) is
    tried and the nearest valid candidate kept.
    """
    v = np.asarray(verts, dtype=np.float64)
    x = np.asarray(u, dtype=np.float64)
    s, nv, _ = v.shape
    best = np.full(s, np.inf)
    best_pt = np.zeros((s, v.shape[2]))
    for r in range(1, nv + 1):
        for subset in itertools.combinations(range(nv), r):
            sub = v[:, subset]  # [S, r, M]
            base = sub[:, 0]
            if r == 1:
                pt = base
                ok = np.ones(s, dtype=bool)
            else:
                e = sub[:, 1:] - base[:, None]  # [S, r-1, M]
                g = np.einsum("sim,sjm->sij", e, e)
                rhs = np.einsum("sim,sm->si", e, x - base)
                det_ok = np.abs(np.linalg.det(g)) > 1e-18
                g = np.where(det_ok[:, None, None], g, np.eye(r - 1))
                lam = np.linalg.solve(g, rhs[..., None])[..., 0]
                ok = det_ok & np.all(lam >= 0.0, axis=-1) & (lam.sum(axis=-1) <= 1.0)
                pt = base + np.einsum("si,sim->sm", lam, e)
            d = np.linalg.norm(pt - x, axis=-1)
            better = ok & (d < best)
            best = np.where(better, d, best)
            best_pt = np.where(better[:, None], pt, best_pt)
    return best_pt, best


@jit.njit
def _line_range_compiled(inv: F, ok: NDArray[np.bool_], x: F, axis: int, lo: F, hi: F) -> None:
    """:meth:`FeasibleSet.line_range` for points ``x [B, N]``, compiled (same sums, same order)."""
    for r in range(x.shape[0]):
        lo[r], hi[r] = line_range_row(inv, ok, x[r], axis)


@jit.njit
def line_range_row(inv: F, ok: NDArray[np.bool_], x: F, axis: int) -> tuple[float, float]:
    """The lowest and highest border crossing along ``axis`` through one point ``x [N]`` (NaN: none), with
    the line systems ``inv``/``ok`` of :meth:`FeasibleSet._line_system`: ``(p₀ + p_N) + p₁ + …`` as numpy sums."""
    n = x.shape[0]
    low, high, found = math.inf, -math.inf, False
    for f in range(inv.shape[0]):
        if not ok[f]:
            continue
        hit, s = True, 0.0
        for i in range(n + 1):
            acc = inv[f, i, 0] * x[0] + inv[f, i, n]
            for j in range(1, n):
                acc = acc + inv[f, i, j] * x[j]
            if i == n:
                s = acc
            elif not acc >= -1e-12:
                hit = False
                break
        if hit:
            found = True
            low, high = min(low, s), max(high, s)
    base = x[axis]
    return (base + low, base + high) if found else (math.nan, math.nan)


@jit.njit
def _contains_compiled(
    values: F, simplices: Ix, inv: F, valid: NDArray[np.bool_], near: Ix, x: F, tol: float, out: NDArray[np.bool_]
) -> None:
    """:meth:`FeasibleSet.contains_many` after its k-d tree query, compiled: the ``near`` simplices of each
    point first, every simplex when none holds it (barycentrics summed in numpy's order)."""
    n = x.shape[1]
    for r in range(x.shape[0]):
        out[r] = False
        for pass_ in range(2):
            count = near.shape[1] if pass_ == 0 else simplices.shape[0]
            for c in range(count):
                s = near[r, c] if pass_ == 0 else c
                if not valid[s]:
                    continue
                v0 = simplices[s, 0]
                total, ok = 0.0, True
                for i in range(n):
                    lam = 0.0
                    for j in range(n):
                        lam = lam + inv[s, i, j] * (x[r, j] - values[v0, j])
                    if not lam >= -tol:
                        ok = False
                        break
                    total = total + lam
                if ok and total <= 1.0 + tol:
                    out[r] = True
                    break
            if out[r]:
                break


@dataclass(frozen=True)
class FeasibleSet:
    """The image of a probe grid in (scaled) property space: inside test and border projection.

    Args:
        grid_shape: probes per axis ``(n₁, …, n_N)``.
        values: ``[P, N]`` measured properties of the probes (C order over the grid),
            already scaled to comparable units.
    """

    grid_shape: tuple[int, ...]
    values: F
    simplices: Ix = field(init=False, repr=False)
    border: Ix = field(init=False, repr=False)
    _inv: F = field(init=False, repr=False)
    _valid: NDArray[np.bool_] = field(init=False, repr=False)
    _centroids: cKDTree = field(init=False, repr=False)
    _line: tuple[tuple[F, NDArray[np.bool_]], ...] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        vals = np.asarray(self.values, dtype=np.float64)
        n = len(self.grid_shape)
        if vals.shape != (int(np.prod(self.grid_shape)), n):
            raise ValueError(
                f"a border needs as many properties as blend axes ({n}) and one row per probe; got {vals.shape}"
            )
        simp = kuhn_simplices(self.grid_shape)
        v = vals[simp]  # [S, N+1, N]
        m = np.swapaxes(v[:, 1:] - v[:, :1], 1, 2)  # columns are edge vectors
        det = np.linalg.det(m)
        valid = np.abs(det) > 1e-14
        inv = np.linalg.inv(np.where(valid[:, None, None], m, np.eye(n)))
        for name, value in (
            ("values", vals),
            ("simplices", simp),
            ("border", border_facets(self.grid_shape, simp)),
            ("_inv", inv),
            ("_valid", valid),
            ("_centroids", cKDTree(v.mean(axis=1))),
        ):
            object.__setattr__(self, name, value)
        object.__setattr__(self, "_line", tuple(self._line_system(axis) for axis in range(n)))

    def _line_system(self, axis: int) -> tuple[F, NDArray[np.bool_]]:
        """Inverses of the border facets' line-crossing systems along ``axis`` (they do not depend on the point).

        Unknowns ``(λ₁…λ_N, s)``: ``Σ λᵢ vᵢ − s·e_axis = u`` and ``Σ λᵢ = 1``.
        """
        v = self.values[self.border]  # [B, N, N]: N vertices of N coordinates
        b, n, _ = v.shape
        a = np.zeros((b, n + 1, n + 1))
        a[:, :n, :n] = np.swapaxes(v, 1, 2)
        a[:, axis, n] = -1.0
        a[:, n, :n] = 1.0
        ok = np.abs(np.linalg.det(a)) > 1e-14
        return np.linalg.inv(np.where(ok[:, None, None], a, np.eye(n + 1))), ok

    def _line_solutions(self, x: F, axis: int) -> tuple[F, NDArray[np.bool_]]:
        """Crossing offsets ``[..., B]`` of lines through ``x [..., N]`` with every facet, and which are hits.

        Each unknown is ``inv·(x, 1)`` summed in a fixed order (first term, the constant, then the
        rest; numpy's einsum's order for ``N = 2``), which :func:`_line_range_compiled` repeats."""
        inv, ok = self._line[axis]
        n = x.shape[-1]
        xs = x[..., None, None, :]
        sol = inv[:, :, 0] * xs[..., 0] + inv[:, :, n]
        for j in range(1, n):
            sol = sol + inv[:, :, j] * xs[..., j]
        hit = ok & np.all(sol[..., :n] >= -1e-12, axis=-1)
        return sol[..., n], hit

    def line_range(self, x: ArrayLike, axis: int) -> tuple[F, F]:
        """Lowest and highest border crossing ``[...]`` along ``axis`` through points ``x [..., N]`` (NaN: none)."""
        xs = np.asarray(x, dtype=np.float64)
        if jit.enabled() and xs.ndim == 2:
            inv, ok = self._line[axis]
            lo, hi = np.empty(len(xs)), np.empty(len(xs))
            _line_range_compiled(inv, ok, xs, axis, lo, hi)
            return lo, hi
        s, hit = self._line_solutions(xs, axis)
        lo = np.where(hit, s, np.inf).min(axis=-1)
        hi = np.where(hit, s, -np.inf).max(axis=-1)
        none = ~hit.any(axis=-1)
        base = xs[..., axis]
        return np.where(none, np.nan, base + lo), np.where(none, np.nan, base + hi)

    def contains_many(self, x: ArrayLike, tol: float = 1e-6) -> NDArray[np.bool_]:
        """:meth:`contains` for points ``x [B, N]`` at once."""
        xs = np.atleast_2d(np.asarray(x, dtype=np.float64))
        k = min(12, len(self.simplices))
        _, near = self._centroids.query(xs, k=k)
        near = near.reshape(len(xs), -1)
        if jit.enabled():
            out = np.empty(len(xs), dtype=np.bool_)
            _contains_compiled(self.values, self.simplices, self._inv, self._valid, near, xs, tol, out)
            return out
        base = self.values[self.simplices[near, 0]]  # [B, k, N]
        lam = np.einsum("bkij,bkj->bki", self._inv[near], xs[:, None, :] - base)
        inside = (self._valid[near] & np.all(lam >= -tol, axis=-1) & (lam.sum(axis=-1) <= 1.0 + tol)).any(axis=-1)
        for i in np.flatnonzero(~inside):
            inside[i] = self._inside(xs[i], slice(None), tol)
        return inside

    def _inside(self, x: F, which: NDArray[np.int64] | slice, tol: float) -> bool:
        base = self.values[self.simplices[which, 0]]
        lam = np.einsum("sij,sj->si", self._inv[which], x - base)
        inside = self._valid[which] & np.all(lam >= -tol, axis=-1) & (lam.sum(axis=-1) <= 1.0 + tol)
        return bool(inside.any())

    def contains(self, u: ArrayLike, tol: float = 1e-6) -> bool:
        """Whether the scaled request ``u [N]`` lies in the image of some grid simplex.

        The simplices whose centroids are nearest are tried first (a k-d tree), which
        settles almost every feasible request in a few microseconds; only a miss
        tests them all.
        """
        x = np.asarray(u, dtype=np.float64)
        k = min(12, len(self.simplices))
        _, near = self._centroids.query(x, k=k)
        if self._inside(x, np.atleast_1d(near), tol):
            return True
        return self._inside(x, slice(None), tol)

    def line_hits(self, u: ArrayLike, axis: int) -> F:
        """Offsets ``s`` where the line ``u + s·e_axis`` crosses the border (sorted, possibly empty)."""
        s, hit = self._line_solutions(np.asarray(u, dtype=np.float64), axis)
        return np.sort(s[hit])

    def nearest(self, u: ArrayLike, weights: ArrayLike | None = None) -> F:
        """The border point nearest ``u`` under the metric ``|diag(weights)·(x − u)|``."""
        x = np.asarray(u, dtype=np.float64)
        w = np.ones_like(x) if weights is None else np.asarray(weights, dtype=np.float64)
        pts, dist = closest_point_on_simplices(self.values[self.border] * w, x * w)
        return pts[int(np.argmin(dist))] / w

    def candidates(self, u: ArrayLike, keep: int, keep_cost: float) -> list[F]:
        """Border points a request outside may move to: the nearest crossing along each
        axis, and the nearest point when moves along ``keep`` cost ``keep_cost`` of their length."""
        x = np.asarray(u, dtype=np.float64)
        out = []
        for axis in range(len(x)):
            hits = self.line_hits(x, axis)
            if len(hits):
                c = x.copy()
                c[axis] += hits[int(np.argmin(np.abs(hits)))]
                out.append(c)
        w = np.ones_like(x)
        w[keep] = keep_cost
        out.append(self.nearest(x, w))
        return out

    def project(self, u: ArrayLike) -> tuple[F, bool]:
        """``(u', inside)``: ``u`` itself when feasible, else the nearest border point."""
        x = np.asarray(u, dtype=np.float64)
        if self.contains(x):
            return x.copy(), True
        return self.nearest(x), False

    def border_polyline(self) -> F:
        """For ``N = 2``: the border as segments ``[B, 2, 2]`` (for plots)."""
        return self.values[self.border]
