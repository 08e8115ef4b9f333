"""The lookup table of thesis §6.2.3: from user-facing properties ``u`` to blend parameters ``p``.

A probe grid ``p*ₖ`` over the blend space is *measured* (each probe's blend is played
and its root speed, crouch height… recorded as ``u*ₖ``); a request ``u`` is then
answered by inverse distance weighting (Eq. 6.1–6.2)::

    p(u) = Σ wₖ p*ₖ / Σ wₖ,   wₖ = 1 / d(u, u*ₖ)^q      (p*ₖ itself when d = 0)

with ``q = 7`` by default. A k-d tree (scipy ``cKDTree``) finds the nearest probes, so
a query costs microseconds with thousands of probes (the weighting after it is one compiled
loop with numba, :mod:`engine.jit`, numpy otherwise); with ``q = 7`` a probe three
grid steps further than the nearest weighs ``3⁻⁷ ≈ 5·10⁻⁴`` of it, so summing the
``k`` nearest (default 16) rather than all probes changes ``p`` by far less than a
grid step's worth and keeps the map continuous to that tolerance.

Beyond the thesis: plain IDW with ``q = 7`` is nearly piecewise constant (every probe
is a flat spot), which costs 12 % worst-case speed error on the puppet's space; each
probe therefore also carries its slope ``∂p/∂u`` from the measured grid and
contributes its first-order expansion (see :meth:`LookupTable.query`), which brings
the worst case under 5 % with the same weights. ``gradients=False`` gives Eq. 6.1 as
printed.

Properties have different units (m/s, m), so distances are taken after scaling each
by its range over the probes. A request outside the feasible set is projected onto
its border (:mod:`engine.blend.feasible`), preferring to change the speed — which
the playback rate makes up — over the height (:meth:`LookupTable.project`), and
playback is sped up by ``u_rate / u'_rate`` along the rate property (root speed), so
a puppet pulled faster than the run still moves its feet at the ground's speed.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TypedDict, Unpack

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial import cKDTree

from engine import jit
from engine.blend.feasible import FeasibleSet

__all__ = ["LookupTable", "Resolution", "probe_grid", "LinearMapping"]

from engine.arrays import F64 as F

_NO_SLOPES = np.zeros((0, 0, 0))  # what the compiled IDW gets for a table without probe slopes


def probe_grid(dims: int, density: int | Sequence[int]) -> tuple[F, tuple[int, ...]]:
    """Probe points ``[P, N]`` on a regular grid over ``[0,1]^N`` (C order) and the grid shape."""
    if isinstance(density, (int, np.integer)):
        shape: tuple[int, ...] = (int(density),) * dims
    else:
        shape = tuple(int(d) for d in density)
    if len(shape) != dims or min(shape) < 2:
        raise ValueError(f"probe density needs at least 2 probes on each of the {dims} axes, got {shape}")
    axes = [np.linspace(0.0, 1.0, s) for s in shape]
    pts = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, dims)
    return pts, shape


@jit.njit
def _idw_kernel(
    x: F, dist: F, idx: NDArray[np.int64], probes: F, scaled: F, slopes: F, use_slopes: bool, power: float, out: F
) -> None:
    """:meth:`LookupTable._idw` for requests ``x [Q, M]`` with their neighbours ``dist``/``idx [Q, k]``, compiled:
    weights ``(d₀/d)^q``, each probe's value (plus its slope times the offset), normalised, clamped to [0, 1]."""
    n, m = probes.shape[1], x.shape[1]
    acc = np.empty(n)
    for r in range(x.shape[0]):
        exact = dist[r, 0] <= 1e-12
        if exact:
            for c in range(n):
                out[r, c] = min(max(probes[idx[r, 0], c], 0.0), 1.0)
            continue
        d0 = dist[r, 0]
        total = 0.0
        for c in range(n):
            acc[c] = 0.0
        for j in range(dist.shape[1]):
            dj = dist[r, j]
            w = min(max(d0 / (dj if dj > 0 else 1.0), 0.0), 1.0) ** power
            total += w
            q = idx[r, j]
            for c in range(n):
                v = probes[q, c]
                if use_slopes:
                    for e in range(m):
                        v += slopes[q, c, e] * (x[r, e] - scaled[q, e])
                acc[c] += w * v
        for c in range(n):
            out[r, c] = min(max(acc[c] / total, 0.0), 1.0)


def _probe_slopes(probes: F, values: F, shape: tuple[int, ...]) -> F:
    """``∂p/∂u [P, N, M]`` at each probe: the inverse of the measured grid's finite-difference Jacobian.

    Where the Jacobian is near-singular (a fold of the map, a flat property) the
    slope is zero and that probe falls back to the plain IDW constant.
    """
    n = len(shape)
    grid_u = values.reshape(shape + (values.shape[1],))
    spacing = [1.0 / (s - 1) for s in shape]
    jac = np.stack(np.gradient(grid_u, *spacing, axis=tuple(range(n))), axis=-1)  # [..., M, N]
    jac = jac.reshape(len(probes), values.shape[1], n)
    slopes = np.zeros((len(probes), n, values.shape[1]))
    if values.shape[1] != n:
        return slopes
    sv = np.linalg.svd(jac, compute_uv=False)
    good = sv[:, -1] > 1e-3 * np.maximum(sv[:, 0], 1e-12)
    slopes[good] = np.linalg.inv(jac[good])
    return slopes


@dataclass(frozen=True)
class LinearMapping:
    """A clamped linear map of one input to one property, ``a ↦ lo``, ``b ↦ hi`` (thesis: phone height → crouch).

    The thesis maps the phone's height straight to ``p_height``; here it maps to the
    *property* (the hips' height in metres), and the lookup table turns that into
    ``p``, so a non-linear height response of the blend is also corrected.
    """

    a: float
    b: float
    lo: float
    hi: float

    def __post_init__(self) -> None:
        if self.a == self.b:
            raise ValueError("a linear mapping needs two distinct input values")

    def __call__(self, x: ArrayLike) -> F:
        t = np.clip((np.asarray(x, dtype=np.float64) - self.a) / (self.b - self.a), 0.0, 1.0)
        return self.lo + t * (self.hi - self.lo)


@dataclass(frozen=True)
class Resolution:
    """The answer to one request: blend point, the feasible request actually played, and the speed-up."""

    point: F
    feasible: F
    inside: bool
    rate: float


class _TableOptions(TypedDict, total=False):
    """The tuning fields of :class:`LookupTable`, as keywords of :meth:`LookupTable.measure`."""

    power: float
    neighbours: int
    rate_property: int | None
    max_rate: float
    keep_cost: float
    gradients: bool


@dataclass(frozen=True)
class LookupTable:
    """Measured probes of a blend space and the IDW inverse map ``u → p``.

    Args:
        probes: ``[P, N]`` blend points of the probes.
        values: ``[P, M]`` measured properties of each probe.
        properties: names of the ``M`` properties, e.g. ``("speed", "height")``.
        grid_shape: the probe grid's shape when the probes form one (enables the border).
        power: IDW power ``q``.
        neighbours: probes summed per query (the k nearest).
        rate_property: index of the property that playback rate scales (speed), or ``None``.
        max_rate: largest speed-up granted outside the feasible set.
        keep_cost: relative cost of changing the rate property when projecting.
        gradients: carry a local slope ``∂p/∂u`` per probe (see :meth:`query`).
    """

    probes: F
    values: F
    properties: tuple[str, ...]
    grid_shape: tuple[int, ...] | None = None
    power: float = 7.0
    neighbours: int = 16
    rate_property: int | None = 0
    max_rate: float = 3.0
    keep_cost: float = 0.1
    gradients: bool = True
    scale: F = field(init=False, repr=False)
    offset: F = field(init=False, repr=False)
    tree: cKDTree = field(init=False, repr=False)
    feasible: FeasibleSet | None = field(init=False, repr=False)
    slopes: F | None = field(init=False, repr=False)
    _scaled_values: F = field(init=False, repr=False)

    def __post_init__(self) -> None:
        p = np.array(self.probes, dtype=np.float64)
        u = np.array(self.values, dtype=np.float64)
        if p.ndim != 2 or u.ndim != 2 or len(p) != len(u) or len(p) == 0:
            raise ValueError(f"probes [P,N] and values [P,M] must have one row per probe; got {p.shape}, {u.shape}")
        if u.shape[1] != len(self.properties):
            raise ValueError(f"values have {u.shape[1]} columns but {len(self.properties)} property names")
        if not (np.isfinite(p).all() and np.isfinite(u).all()):
            raise ValueError("probes or measured values contain NaN or infinite values")
        if self.power <= 0:
            raise ValueError("the IDW power q must be positive")
        offset = u.min(axis=0)
        span = u.max(axis=0) - offset
        scale = np.where(span > 1e-12, span, 1.0)
        for a in (p, u, offset, scale):
            a.setflags(write=False)
        object.__setattr__(self, "probes", p)
        object.__setattr__(self, "values", u)
        object.__setattr__(self, "offset", offset)
        object.__setattr__(self, "scale", scale)
        object.__setattr__(self, "_scaled_values", (u - offset) / scale)
        object.__setattr__(self, "tree", cKDTree((u - offset) / scale))
        feas = None
        if self.grid_shape is not None and u.shape[1] == p.shape[1]:
            feas = FeasibleSet(tuple(self.grid_shape), (u - offset) / scale)
        object.__setattr__(self, "feasible", feas)
        slopes = None
        if self.gradients and self.grid_shape is not None:
            slopes = _probe_slopes(p, (u - offset) / scale, tuple(self.grid_shape))
        object.__setattr__(self, "slopes", slopes)

    @classmethod
    def measure(
        cls,
        dims: int,
        density: int | Sequence[int],
        measure_fn: Callable[[F], F],
        properties: Sequence[str],
        **kw: Unpack[_TableOptions],
    ) -> LookupTable:
        """Build a table by measuring ``measure_fn(probes [P,N]) -> [P,M]`` over a probe grid."""
        probes, shape = probe_grid(dims, density)
        return cls(probes, np.asarray(measure_fn(probes)), tuple(properties), shape, **kw)

    def _scaled(self, u: ArrayLike) -> F:
        x = np.asarray(u, dtype=np.float64)
        if x.shape[-1:] != (len(self.properties),):
            names = ", ".join(self.properties)
            raise ValueError(f"a request needs {len(self.properties)} values ({names}), got {x.shape}")
        x = (x - self.offset) / self.scale
        if not np.isfinite(x).all():
            raise ValueError("request contains NaN or infinite values")
        return x

    def _idw(self, x: F, dist: F, idx: NDArray[np.int64]) -> F:
        if jit.enabled():
            k, n = dist.shape[-1], self.probes.shape[1]
            flat = dist.reshape(-1, k)
            out = np.empty((flat.shape[0], n))
            _idw_kernel(
                x.reshape(-1, x.shape[-1]),
                flat,
                idx.reshape(-1, k),
                self.probes,
                self._scaled_values,
                _NO_SLOPES if self.slopes is None else self.slopes,
                self.slopes is not None,
                float(self.power),
                out,
            )
            return out.reshape(dist.shape[:-1] + (n,))
        exact = dist[..., 0] <= 1e-12
        # Weights relative to the nearest probe: (d0/d)^q stays finite for any q.
        d0 = np.where(exact[..., None], 1.0, dist[..., :1])
        w = np.clip(d0 / np.where(dist > 0, dist, 1.0), 0.0, 1.0) ** self.power
        values = self.probes[idx]
        if self.slopes is not None:
            delta = (x[..., None, :] - self._scaled_values[idx])[..., None]
            values = values + (self.slopes[idx] @ delta)[..., 0]
        p = (w[..., None, :] @ values)[..., 0, :] / w.sum(axis=-1, keepdims=True)
        return np.clip(np.where(exact[..., None], self.probes[idx[..., 0]], p), 0.0, 1.0)

    def query(self, u: ArrayLike) -> F:
        """Blend point(s) ``p [..., N]`` for request(s) ``u [..., M]`` by IDW over the k nearest probes.

        Plain IDW with a high power has flat spots: near a probe ``p`` sticks to that
        probe (zero slope), so a request 30 % of the way to the next probe plays
        nearly the probe's speed — at low speeds a large relative error. With
        ``gradients`` (default) each probe contributes its first-order Taylor
        expansion ``p*ₖ + Gₖ(u − u*ₖ)`` instead of the constant ``p*ₖ`` (Shepard's
        method with nodal gradients, as in Franke & Nielson's modified Shepard),
        where ``Gₖ = (∂u/∂p)⁻¹`` comes from finite differences of the measured grid.
        The weights ``wₖ`` are Eq. 6.2 unchanged, so the map is still exact at the
        probes, continuous, and local; it now also reproduces locally linear maps.
        """
        return self.query_scaled(self._scaled(u))

    def query_scaled(self, x: F) -> F:
        """:meth:`query` of requests already scaled to the table's units (``(u − offset) / scale``, finite)."""
        k = min(self.neighbours, len(self.probes))
        dist, idx = self.tree.query(x, k=k)
        if k == 1:
            dist, idx = dist[..., None], idx[..., None]
        return self._idw(x, np.asarray(dist), np.asarray(idx))

    def query_brute(self, u: ArrayLike) -> F:
        """The same IDW summed over every probe, without the tree (the baseline of the bench)."""
        x = self._scaled(u)
        dist = np.linalg.norm(x[..., None, :] - self._scaled_values, axis=-1)
        order = np.argsort(dist, axis=-1)
        return self._idw(x, np.take_along_axis(dist, order, axis=-1), order)

    def project(self, u: ArrayLike) -> tuple[F, bool]:
        """``(u', inside)`` in property units: ``u`` if feasible, else a point of the border.

        Without a rate property this is the nearest border point (in scaled units).
        With one (speed), the candidates are the nearest border crossing along each
        property axis and the nearest point when speed changes count a tenth, and
        the cheapest wins: cost is the scaled change, speed changes at a tenth —
        the speed-up ``u/u'`` makes them up — unless that speed-up would exceed
        ``max_rate`` (then the feet would slide, so the candidate is a last resort).
        So a puppet asked to run too fast keeps its height and runs sped up; one asked
        to crouch lower than it can crouches as low as it can *at the requested
        speed*; a request a hair above the standing height is lowered, not slowed.
        """
        fs = self.feasible
        if fs is None:
            raise ValueError("this table has no feasible border: it needs a probe grid with one property per axis")
        x = self._scaled(u)
        if fs.contains(x):
            return x * self.scale + self.offset, True
        if self.rate_property is None:
            return fs.nearest(x) * self.scale + self.offset, False
        k = self.rate_property
        want = float(np.asarray(u, dtype=np.float64)[k])
        best, best_cost = x, np.inf
        for c in fs.candidates(x, k, self.keep_cost):
            d = c - x
            d[k] *= self.keep_cost
            cost = float(np.linalg.norm(d))
            got = float(c[k] * self.scale[k] + self.offset[k])
            if abs(want - got) > 1e-9 and not (want * got > 0 and 1.0 / self.max_rate <= want / got <= self.max_rate):
                cost += 1e3
            if cost < best_cost:
                best, best_cost = c, cost
        return best * self.scale + self.offset, False

    def extent(self, u: ArrayLike, axis: int) -> tuple[float, float] | None:
        """The lowest and highest feasible value of property ``axis`` with the others as in ``u``.

        E.g. the standing (tallest) hips height at a given speed. ``None`` when the
        line misses the feasible set or the table has no border.
        """
        if self.feasible is None:
            return None
        hits = self.feasible.line_hits(self._scaled(u), axis)
        if not len(hits):
            return None
        x = self._scaled(u)[axis]
        return float((x + hits[0]) * self.scale[axis] + self.offset[axis]), float(
            (x + hits[-1]) * self.scale[axis] + self.offset[axis]
        )

    def resolve_many(self, u: ArrayLike) -> tuple[F, F, NDArray[np.bool_], F]:
        """:meth:`resolve` for requests ``u [B, M]`` at once: points, feasible requests, inside flags, rates.

        Feasible requests (the common case) take one batched inside test and one
        batched tree query; only the ones outside are projected one by one.
        """
        req = np.atleast_2d(np.asarray(u, dtype=np.float64))
        feasible = req.copy()
        inside = np.ones(len(req), dtype=bool)
        rate = np.ones(len(req))
        if self.feasible is not None:
            inside = self.feasible.contains_many(self._scaled(req))
            for i in np.flatnonzero(~inside):
                res = self.resolve(req[i])
                feasible[i], inside[i], rate[i] = res.feasible, res.inside, res.rate
        return self.query(feasible), feasible, inside, rate

    def extent_many(self, u: ArrayLike, axis: int) -> tuple[F, F]:
        """:meth:`extent` for points ``u [B, M]``: lowest and highest feasible values (NaN where none)."""
        if self.feasible is None:
            raise ValueError("this table has no feasible border")
        lo, hi = self.feasible.line_range(self._scaled(u), axis)
        return lo * self.scale[axis] + self.offset[axis], hi * self.scale[axis] + self.offset[axis]

    def resolve(self, u: ArrayLike) -> Resolution:
        """One request end to end: project if needed, look up ``p``, and the playback speed-up ``u/u'``."""
        req = np.asarray(u, dtype=np.float64)
        if self.feasible is None:
            return Resolution(self.query(req), req.copy(), True, 1.0)
        proj, inside = self.project(req)
        rate = 1.0
        if not inside and self.rate_property is not None:
            want = float(req[self.rate_property])
            got = float(proj[self.rate_property])
            if abs(got) > 1e-6 and want * got > 0:
                rate = float(np.clip(want / got, 1.0 / self.max_rate, self.max_rate))
        return Resolution(self.query(proj), proj, inside, rate)
