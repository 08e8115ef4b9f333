"""A network of flow curves converging on a centre-point (§3.4.2, Eq. 3.7–3.8).

1. **Average curves.** Each open SEcurve is extended from both ends by integrating the
   inverse-distance-weighted direction of the other SEcurves nearby (Eq. 3.7, kernel
   ``r(d) = 1/(1+d²)``, neighbours within ``d_Max`` and ``θ_Max = π/3``), until no
   neighbour qualifies. Curves that steered one another are clustered; each cluster's
   curves, put on a common parameter, are averaged and smoothed with Eq. 3.6.
2. **Bending.** Each average curve keeps one end (position and tangent) and bends the
   rest to point at the centre-point (Eq. 3.8, w1 = 500, w2 = 0.5, w3 = 7); curves that
   would change too much are dropped. The thesis keeps whichever end gives the smaller
   change of shape; we keep the end *farther* from the centre-point: tried on the field,
   the smaller change was often a hook at the tip (a tangent turned at the last pixels),
   where a tree planted in the ground should rather lean its top towards the point.

The thesis leaves the terms' scales open: the length term is in pixels as written
(10 px of change cost as much as θ_p = 0.1 rad; its ``|·|`` rounded over 1 px so it is smooth), the curvature term is made
dimensionless, ``∫‖γ''‖² ds / l²`` (a circular arc turning by φ scores φ²), and θ_p is the angle
between the tip tangent and the direction from the tip *to* the centre-point (the
thesis writes ``γ(1) − x_p``, which would point away from it). Dragging the
centre-point re-bends from the last answer (a warm start: Newton steps for all curves in
one vectorised batch), so it updates live.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal, overload

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import minimize

from authoring.flowcurves.hermite import Hermite, basis, fit_stroke, resample_polyline, tangents

__all__ = ["average_curves", "bend_curve", "rebend", "FlowNetwork", "tip_angle", "D_MAX", "THETA_MAX"]

from engine.arrays import F64 as F

D_MAX, THETA_MAX = 60.0, math.pi / 3.0
W1, W2, W3 = 500.0, 0.5, 7.0
#: The length term's ``|L − l0|`` is taken as ``√((L − l0)² + ε²) − ε``: within 0.5 energy units of it
#: (ε = 1 px, W2 = 0.5) and smooth, where its kink at ``L = l0`` — where the minimum usually lies — held
#: quasi-Newton steps to dozens of iterations.
LENGTH_SMOOTHING = 1.0
#: Integration step of Eq. 3.7 (pixels) and its cap (a curve extends at most this many steps a side).
STEP, MAX_STEPS = 5.0, 120
#: A bent curve whose mean distance to its average curve exceeds this fraction of its length is dropped.
MAX_CHANGE = 0.6
_SAMPLES = 48


def _extend(curve: F, others: list[tuple[int, F, F]], d_max: float, theta_max: float) -> tuple[F, set[int]]:
    """Eq. 3.7 from the curve's last point onwards; returns the added points and who steered them."""
    p = curve[-1].copy()
    direction = tangents(curve)[-1]
    added, used = [], set()
    for _ in range(MAX_STEPS):
        num, den = np.zeros(2), 0.0
        for k, pts, tan in others:
            d2 = ((pts - p) ** 2).sum(axis=1)
            i = int(np.argmin(d2))
            d = math.sqrt(d2[i])
            t = tan[i] if tan[i] @ direction >= 0 else -tan[i]
            if d >= d_max or math.acos(float(np.clip(t @ direction, -1, 1))) >= theta_max:
                continue
            r = 1.0 / (1.0 + d * d)
            num, den = num + r * t, den + r
            used.add(k)
        if den == 0.0:
            break
        direction = num / den
        direction /= max(float(np.linalg.norm(direction)), 1e-12)
        p = p + STEP * direction
        added.append(p.copy())
    return (np.array(added) if added else np.zeros((0, 2))), used


def average_curves(
    curves: list[F], screen_width: float, d_max: float = D_MAX, theta_max: float = THETA_MAX
) -> list[Hermite]:
    """Step 1: extended, clustered and averaged SEcurves as smooth Hermite curves."""
    curves = [resample_polyline(c, max(8, len(c))) for c in curves if len(c) >= 2]
    data = [(k, c, tangents(c)) for k, c in enumerate(curves)]
    parent = list(range(len(curves)))

    def root(a: int) -> int:
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    extended = []
    for k, c in enumerate(curves):
        others = [d for d in data if d[0] != k]
        tail, used_t = _extend(c, others, d_max, theta_max)
        head, used_h = _extend(c[::-1], others, d_max, theta_max)
        extended.append(np.vstack([head[::-1], c, tail]))
        for j in used_t | used_h:
            parent[root(j)] = root(k)
    clusters: dict[int, list[int]] = {}
    for k in range(len(curves)):
        clusters.setdefault(root(k), []).append(k)
    out = []
    for members in clusters.values():
        ref = resample_polyline(extended[members[0]], _SAMPLES)
        acc = []
        for k in members:
            q = resample_polyline(extended[k], _SAMPLES)
            if np.sum((q - ref) ** 2) > np.sum((q[::-1] - ref) ** 2):
                q = q[::-1]
            acc.append(q)
        out.append(fit_stroke(np.mean(acc, axis=0), screen_width))
    return out


def tip_angle(curve: Hermite, centre: ArrayLike) -> float:
    """θ_p: angle between the tangent at γ(1) and the direction from γ(1) to the centre-point."""
    tip, tan = curve(1.0)[0], curve(1.0, order=1)[0]
    to = np.asarray(centre, dtype=np.float64) - tip
    den = float(np.linalg.norm(to) * np.linalg.norm(tan))
    if den < 1e-12:
        return 0.0
    return math.acos(float(np.clip(to @ tan / den, -1.0, 1.0)))


class _Bend:
    """Eq. 3.8's objective for ``b`` curves of ``n`` control points, basis matrices built once.

    Evaluated for ``k`` candidates of each curve at once (``free``: ``[b, k, 4n−4]``), with its
    exact gradient: one vectorised call serves a quasi-Newton step, a Hessian by differences of
    gradients, or a line search, for every curve of a network together. The angle is written
    as a signed ``atan2``, whose square is θ_p² and smooth through θ_p = 0 (``arccos`` is not).
    """

    def __init__(self, n: int, fixed: F, centre: F, l0: F) -> None:
        self.n, self.centre = n, centre
        self.fixed, self.l0 = fixed[:, None], l0[:, None]  # [b, 1, 2, 2], [b, 1]
        self.b0 = basis(np.linspace(0.0, 1.0, 48), n)
        self.b1 = basis([1.0], n, order=1)[0]
        self.b2 = basis(np.linspace(0.0, 1.0, 64), n, order=2)

    def assemble(self, free: F) -> F:
        """``[b, k, 2n, 2]`` control points and tangents from the free variables ``[b, k, 4n−4]``."""
        n = self.n
        f = free.reshape(*free.shape[:-1], 2 * n - 2, 2)
        fix = np.broadcast_to(self.fixed, (*free.shape[:-1], 2, 2))
        return np.concatenate([fix[..., 0:1, :], f[..., : n - 1, :], fix[..., 1:2, :], f[..., n - 1 :, :]], axis=-2)

    def _free(self, gq: F) -> F:
        n = self.n
        return np.concatenate([gq[..., 1:n, :], gq[..., n + 1 :, :]], axis=-2).reshape(*gq.shape[:-2], -1)

    @overload
    def batch(self, free: F, gradient: Literal[False] = False) -> F: ...
    @overload
    def batch(self, free: F, gradient: Literal[True]) -> tuple[F, F]: ...
    def batch(self, free: F, gradient: bool = False) -> F | tuple[F, F]:
        """Energies ``[b, k]`` of the candidates ``[b, k, 4n−4]`` (and their gradients, shaped as ``free``)."""
        q = self.assemble(free)
        p = self.b0 @ q
        d = np.diff(p, axis=-2)
        seg = np.linalg.norm(d, axis=-1)
        length = seg.sum(axis=-1)
        tan = np.squeeze(self.b1[None] @ q, axis=-2)
        to = self.centre - p[..., -1, :]
        dot = np.sum(to * tan, axis=-1)
        cross = to[..., 0] * tan[..., 1] - to[..., 1] * tan[..., 0]
        phi = np.arctan2(cross, dot)  # ±θ_p
        r2 = self.b2 @ q
        smooth = np.mean(np.sum(r2**2, axis=-1), axis=-1)
        lc = np.maximum(length, 1e-9)
        change = np.sqrt((length - self.l0) ** 2 + LENGTH_SMOOTHING**2)  # |L − l0|, rounded over ~1 px
        energy = W1 * phi**2 + W2 * (change - LENGTH_SMOOTHING) + W3 * smooth / lc**2
        if not gradient:
            return energy
        u = d / np.maximum(seg, 1e-12)[..., None]
        g_p = np.zeros_like(p)
        g_p[..., :-1, :] -= u
        g_p[..., 1:, :] += u
        g_len = self.b0.T @ g_p  # dL/dq
        den = np.maximum(dot**2 + cross**2, 1e-24)[..., None]
        perp_to = np.stack([-to[..., 1], to[..., 0]], axis=-1)
        perp_tan = np.stack([tan[..., 1], -tan[..., 0]], axis=-1)
        d_tan = (dot[..., None] * perp_to - cross[..., None] * to) / den
        d_to = (dot[..., None] * perp_tan - cross[..., None] * tan) / den
        g_phi = self.b1[:, None] * d_tan[..., None, :] - self.b0[-1][:, None] * d_to[..., None, :]
        g_smooth = (self.b2.T @ r2) * (2.0 / len(self.b2))
        ex = (..., None, None)
        g_bend = g_smooth / (lc**2)[ex] - (2.0 * smooth / lc**3)[ex] * g_len
        gq = (2.0 * W1 * phi)[ex] * g_phi + (W2 * (length - self.l0) / change)[ex] * g_len + W3 * g_bend
        return energy, self._free(gq)

    def __call__(self, free: F) -> tuple[float, F]:
        e, g = self.batch(free[None, None], gradient=True)
        return float(e[0, 0]), g[0, 0]


def _problem(curves: list[Hermite], centre: ArrayLike) -> _Bend:
    """Eq. 3.8 for curves of one control-point count, each holding its ``γ(0)``, ``γ'(0)`` and length."""
    n = curves[0].n
    fixed = np.stack([np.vstack([c.q[0], c.q[n]]) for c in curves])
    return _Bend(n, fixed, np.asarray(centre, dtype=np.float64), np.array([c.length(48) for c in curves]))


def _free_of(curve: Hermite) -> F:
    n = curve.n
    return np.vstack([curve.q[1:n], curve.q[n + 1 :]]).ravel()


def bend_curve(curve: Hermite, centre: ArrayLike, start: Hermite | None = None, max_iterations: int = 200) -> Hermite:
    """Eq. 3.8 with ``γ(0)`` and ``γ'(0)`` held: the rest of the curve turns to point at ``centre``."""
    energy = _problem([curve], centre)
    res = minimize(
        energy, _free_of(start or curve), jac=True, method="BFGS", options={"maxiter": max_iterations, "gtol": 1e-5}
    )
    return Hermite(energy.assemble(res.x[None, None])[0, 0])


#: Step lengths tried at once by :func:`rebend` (a line search as one vectorised evaluation).
_STEPS: F = np.asarray(2.0 ** -np.arange(-2, 24), dtype=np.float64)  # (the stubs type the power as floating)


def rebend(curves: list[Hermite], centre: ArrayLike, starts: list[Hermite], iterations: int = 12) -> list[Hermite]:
    """Eq. 3.8 for many curves at once from nearby answers (a drag): damped Newton steps.

    Curves with the same control-point count are one batch. The Hessian is differences of
    exact gradients (one call for every curve), made positive definite by taking its
    eigenvalues' magnitudes; every step length of :data:`_STEPS` is tried in one call and the
    lowest energy kept, so a curve never gets worse than its start. From the previous drag
    position's curves this reaches the cold BFGS minimum in a few steps (measured over the
    editor's scripted drag on the snowman field: the same curves as a cold build to 0.003 px,
    most of them after 3 steps).
    """
    out: dict[int, Hermite] = {}
    groups: dict[int, list[int]] = {}
    for i, c in enumerate(curves):
        groups.setdefault(c.n, []).append(i)
    for members in groups.values():
        energy = _problem([curves[i] for i in members], centre)
        x = np.stack([_free_of(starts[i]) for i in members])  # [b, m]
        b, m = x.shape
        for _ in range(iterations):
            h = 1e-5 * np.maximum(1.0, np.abs(x))
            probes = x[:, None, :] + np.concatenate([np.zeros((1, m)), np.eye(m)])[None] * h[:, None, :]
            values, grads = energy.batch(probes, gradient=True)  # at x, then one step along each variable
            e, g = values[:, 0], grads[:, 0]
            hess = (grads[:, 1:] - g[:, None, :]) / h[:, :, None]
            w, v = np.linalg.eigh(0.5 * (hess + np.swapaxes(hess, 1, 2)))
            w = np.maximum(np.abs(w), 1e-8 * np.abs(w).max(axis=1, keepdims=True) + 1e-12)
            step = -np.einsum("bij,bj->bi", v, np.einsum("bji,bj->bi", v, g) / w)
            tried = energy.batch(x[:, None, :] + _STEPS[None, :, None] * step[:, None, :])
            best = np.argmin(tried, axis=1)
            better = tried[np.arange(b), best] < e - 1e-8 * (1.0 + np.abs(e))  # converged curves stop
            if not better.any():
                break
            x = np.where(better[:, None], x + _STEPS[best][:, None] * step, x)
        q = energy.assemble(x[:, None])[:, 0]
        for row, i in enumerate(members):
            out[i] = Hermite(q[row])
    return [out[i] for i in range(len(curves))]  # every curve is in one group


def _reverse(curve: Hermite) -> Hermite:
    n = curve.n
    return Hermite(np.vstack([curve.q[:n][::-1], -curve.q[n:][::-1]]))


def _closer_start(curve: Hermite, centre: F) -> bool:
    """Whether γ(0) is nearer the centre-point than γ(1)."""
    ends = curve(np.array([0.0, 1.0]))
    return bool(np.linalg.norm(ends[0] - centre) < np.linalg.norm(ends[1] - centre))


def _change(a: Hermite, b: Hermite) -> float:
    return float(np.mean(np.linalg.norm(a.sample(_SAMPLES) - b.sample(_SAMPLES), axis=1)))


@dataclass
class FlowNetwork:
    """The flow curves converging on a centre-point, re-bent from the last ones as it moves."""

    averages: list[Hermite]
    centre: F
    curves: list[Hermite]

    @classmethod
    def build(cls, securves: list[F], centre: ArrayLike, screen_width: float, d_max: float = D_MAX) -> FlowNetwork:
        net = cls(average_curves(securves, screen_width, d_max), np.asarray(centre, dtype=np.float64), [])
        net.move(centre)
        return net

    def move(self, centre: ArrayLike, warm: bool = False) -> None:
        """Re-bend every average curve towards the centre-point.

        Cold, each curve keeps its end farther from the point and BFGS bends it from its
        average; ``warm`` (a drag) keeps the ends chosen last time and takes a few Newton
        steps for all curves together from the last bent ones (:func:`rebend`).
        """
        self.centre = np.asarray(centre, dtype=np.float64)
        previous = {id(a): (b, g) for a, b, g in getattr(self, "_chosen", [])} if warm else {}
        again = [previous[id(avg)] for avg in self.averages if id(avg) in previous]
        rebent = iter(rebend([b for b, _ in again], self.centre, [g for _, g in again]) if again else [])
        chosen: list[tuple[Hermite, Hermite, Hermite]] = []  # (average, oriented base, bent)
        for avg in self.averages:
            if id(avg) in previous:
                chosen.append((avg, previous[id(avg)][0], next(rebent)))
            else:
                base = _reverse(avg) if _closer_start(avg, self.centre) else avg
                chosen.append((avg, base, bend_curve(base, self.centre)))
        self._chosen = chosen
        self.curves = [g for a, b, g in chosen if _change(g, b) <= MAX_CHANGE * a.length()]
