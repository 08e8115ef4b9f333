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
(10 px of change cost as much as θ_p = 0.1 rad), the curvature term is made
dimensionless, ``∫‖γ''‖² ds / l²`` (a circular arc turning by φ scores φ²), and θ_p is the angle
between the tip tangent and the direction from the tip *to* the centre-point (the
thesis writes ``γ(1) − x_p``, which would point away from it). Dragging the
centre-point re-bends from the last answer (a warm start), so it updates live.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import minimize

from authoring.flowcurves.hermite import Hermite, basis, fit_stroke, resample_polyline, tangents

__all__ = ["average_curves", "bend_curve", "FlowNetwork", "tip_angle", "D_MAX", "THETA_MAX"]

F = NDArray[np.float64]

#: d_Max is the user's grouping radius (the editor's ``[``/``]``); 60 px groups only close curves.
D_MAX, THETA_MAX = 60.0, math.pi / 3.0
W1, W2, W3 = 500.0, 0.5, 7.0
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


def average_curves(curves: list[F], screen_width: float, d_max: float = D_MAX,
                   theta_max: float = THETA_MAX) -> list[Hermite]:
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
    """Eq. 3.8's objective for curves of ``n`` control points, with its basis matrices built once.

    Evaluated for a batch of candidate curves at once, so the forward-difference gradient
    (one candidate per degree of freedom) is one vectorised call rather than 4n−4 calls.
    """

    def __init__(self, n: int, fixed: F, centre: F, l0: float) -> None:
        self.n, self.fixed, self.centre, self.l0 = n, fixed, centre, l0
        self.b0 = basis(np.linspace(0.0, 1.0, 48), n)
        self.b1 = basis([1.0], n, order=1)[0]
        self.b2 = basis(np.linspace(0.0, 1.0, 64), n, order=2)

    def assemble(self, free: F) -> F:
        """``[..., 2n, 2]`` control points and tangents from the free variables ``[..., 4n−4]``."""
        n = self.n
        f = free.reshape(*free.shape[:-1], 2 * n - 2, 2)
        fix = np.broadcast_to(self.fixed, (*free.shape[:-1], 2, 2))
        return np.concatenate([fix[..., 0:1, :], f[..., : n - 1, :], fix[..., 1:2, :], f[..., n - 1:, :]], axis=-2)

    def batch(self, free: F) -> F:
        q = self.assemble(free)
        p = np.einsum("sk,bkd->bsd", self.b0, q)
        length = np.linalg.norm(np.diff(p, axis=1), axis=2).sum(axis=1)
        tan = np.einsum("k,bkd->bd", self.b1, q)
        to = self.centre - p[:, -1]
        den = np.linalg.norm(to, axis=1) * np.linalg.norm(tan, axis=1)
        cos = np.where(den > 1e-12, np.sum(to * tan, axis=1) / np.maximum(den, 1e-12), 1.0)
        theta = np.arccos(np.clip(cos, -1.0, 1.0))
        bend = np.mean(np.sum(np.einsum("sk,bkd->bsd", self.b2, q) ** 2, axis=2), axis=1) / np.maximum(length, 1e-9) ** 2
        return W1 * theta**2 + W2 * np.abs(length - self.l0) + W3 * bend

    def __call__(self, free: F) -> float:
        return float(self.batch(free[None])[0])

    def gradient(self, free: F) -> F:
        h = 1e-6 * np.maximum(1.0, np.abs(free))
        probes = free[None] + np.diag(h)
        values = self.batch(np.vstack([free[None], probes]))
        return (values[1:] - values[0]) / h


def bend_curve(curve: Hermite, centre: ArrayLike, start: Hermite | None = None, max_iterations: int = 200) -> Hermite:
    """Eq. 3.8 with ``γ(0)`` and ``γ'(0)`` held: the rest of the curve turns to point at ``centre``."""
    n, q0 = curve.n, curve.q
    energy = _Bend(n, np.vstack([q0[0], q0[n]]), np.asarray(centre, dtype=np.float64), curve.length(48))
    init = (start or curve).q
    free0 = np.vstack([init[1:n], init[n + 1:]]).ravel()
    res = minimize(energy, free0, jac=energy.gradient, method="BFGS", options={"maxiter": max_iterations, "gtol": 1e-5})
    return Hermite(energy.assemble(res.x))


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

        Cold, both ends are tried and the smaller change kept; ``warm`` (a drag) keeps the
        end chosen last time and starts from the last bent curve, a few quasi-Newton steps.
        """
        self.centre = np.asarray(centre, dtype=np.float64)
        chosen: list[tuple[Hermite, Hermite, Hermite]] = []  # (average, oriented base, bent)
        previous = {id(a): (b, g) for a, b, g in getattr(self, "_chosen", [])} if warm else {}
        for avg in self.averages:
            if id(avg) in previous:
                base, last = previous[id(avg)]
                options = [(base, bend_curve(base, self.centre, last, max_iterations=30))]
            else:
                near_end = _reverse(avg) if _closer_start(avg, self.centre) else avg
                options = [(near_end, bend_curve(near_end, self.centre))]
            base, bent = min(options, key=lambda o: _change(o[1], o[0]))
            chosen.append((avg, base, bent))
        self._chosen = chosen
        self.curves = [g for a, b, g in chosen if _change(g, b) <= MAX_CHANGE * a.length()]
