"""Cubic Hermite curves in screen space, as linear maps of their control points and tangents.

Every curve of chapter 3 — principal curves (Eq. 3.1), contours (Eq. 3.2–3.5), flow
curves (Eq. 3.6, 3.8) — is a cubic Hermite spline. Writing a sampled curve as ``B @ q``
(``q``: ``[2n, 2]``, the n positions then the n tangents) turns the fits of Eq. 3.1 and
3.6 into linear least squares, solved exactly instead of iterated.

The parameter ``s`` runs over ``[0, 1]`` for the whole curve; derivatives are taken with
respect to ``s`` (so an open straight curve of length ``l`` has ``|c'(s)| = l``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["Hermite", "basis", "fit_stroke", "control_count", "resample_polyline", "polyline_length", "tangents"]

from engine.arrays import F64 as F

#: curvature integral is taken over arc length in pixels (∫κ² dσ, so long strokes are not smoothed
#: more than short ones). w2 = 100 px³: a bend of radius 200 px over 600 px costs ~1.5 px², kept;
#: a 3 px wiggle every 40 px costs ~170 px² against ~5 px² of fit, smoothed away.
W_FIT, W_CURVATURE = 1.0, 100.0


def _segments(s: F, n: int, closed: bool) -> tuple[NDArray[np.int64], F, int]:
    m = n if closed else n - 1
    u = np.clip(np.asarray(s, dtype=np.float64), 0.0, 1.0) * m
    k = np.minimum(np.floor(u).astype(np.int64), m - 1)
    return k, u - k, m


def basis(s: ArrayLike, n: int, closed: bool = False, order: int = 0) -> F:
    """``[len(s), 2n]`` matrix of the ``order``-th derivative (0, 1, 2) of the curve at ``s``."""
    s = np.atleast_1d(np.asarray(s, dtype=np.float64))
    k, t, m = _segments(s, n, closed)
    if order == 0:
        h = np.stack([2 * t**3 - 3 * t**2 + 1, t**3 - 2 * t**2 + t, -2 * t**3 + 3 * t**2, t**3 - t**2], axis=1)
    elif order == 1:
        h = np.stack([6 * t**2 - 6 * t, 3 * t**2 - 4 * t + 1, -6 * t**2 + 6 * t, 3 * t**2 - 2 * t], axis=1) * m
    elif order == 2:
        h = np.stack([12 * t - 6, 6 * t - 4, -12 * t + 6, 6 * t - 2], axis=1) * m * m
    else:
        raise ValueError(f"derivative order must be 0, 1 or 2, not {order}")
    j = (k + 1) % n
    out = np.zeros((len(s), 2 * n))
    rows = np.arange(len(s))
    # Tangents are per unit of s; a segment spans 1/m of s, hence the 1/m on the tangent basis.
    np.add.at(out, (rows, k), h[:, 0])
    np.add.at(out, (rows, n + k), h[:, 1] / m)
    np.add.at(out, (rows, j), h[:, 2])
    np.add.at(out, (rows, n + j), h[:, 3] / m)
    return out


@dataclass
class Hermite:
    """A cubic Hermite curve: ``q[:n]`` positions, ``q[n:]`` tangents (per unit of s)."""

    q: F
    closed: bool = False

    @property
    def n(self) -> int:
        """Number of control points."""
        return len(self.q) // 2

    def __call__(self, s: ArrayLike, order: int = 0) -> F:
        return basis(s, self.n, self.closed, order) @ self.q

    def sample(self, count: int = 64, order: int = 0) -> F:
        """``count`` points at equal steps of ``s`` (a closed curve does not repeat its start)."""
        s = np.linspace(0.0, 1.0, count, endpoint=not self.closed)
        return self(s, order)

    def length(self, count: int = 128) -> float:
        """Arc length from a polyline of ``count`` samples."""
        p = self.sample(count)
        if self.closed:
            p = np.vstack([p, p[:1]])
        return polyline_length(p)

    @classmethod
    def line(cls, a: ArrayLike, b: ArrayLike, n: int) -> Hermite:
        """The straight curve from ``a`` to ``b`` with ``n`` control points."""
        a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
        pts = a + np.linspace(0.0, 1.0, n)[:, None] * (b - a)
        return cls(np.vstack([pts, np.tile(b - a, (n, 1))]))


def polyline_length(p: ArrayLike) -> float:
    """Length of a polyline ``[N, 2]``."""
    p = np.asarray(p, dtype=np.float64)
    return float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum()) if len(p) > 1 else 0.0


def chord_parameters(p: F) -> F:
    """Chord-length parameters in [0, 1] of polyline points."""
    d = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))]
    return d / d[-1] if d[-1] > 0 else np.linspace(0.0, 1.0, len(p))


def resample_polyline(p: ArrayLike, count: int) -> F:
    """``count`` points at equal arc length along a polyline."""
    p = np.asarray(p, dtype=np.float64)
    if len(p) == 1:
        return np.repeat(p, count, axis=0)
    s = chord_parameters(p)
    u = np.linspace(0.0, 1.0, count)
    return np.c_[np.interp(u, s, p[:, 0]), np.interp(u, s, p[:, 1])]


def tangents(p: ArrayLike) -> F:
    """Unit tangents of a polyline (central differences; one-sided at the ends)."""
    d = np.gradient(np.asarray(p, dtype=np.float64), axis=0)
    n = np.linalg.norm(d, axis=1, keepdims=True)
    return d / np.maximum(n, 1e-12)


def control_count(length: float, screen_width: float) -> int:
    """``n_γ = ⌈3 · 4 · l_γ / w_s⌉ + 1`` control points for a stroke (§3.4.1), at least 2."""
    return max(2, math.ceil(3 * 4 * length / screen_width) + 1)


def fit_stroke(
    samples: ArrayLike,
    screen_width: float,
    n: int | None = None,
    w_fit: float = W_FIT,
    w_curvature: float = W_CURVATURE,
) -> Hermite:
    """Eq. 3.6: the Hermite curve through stroke samples with a curvature penalty.

    Samples are parametrised by chord length; the curvature integral uses 64 equally
    spaced points. Solved as one linear least-squares problem in all positions and tangents.
    """
    f = np.asarray(samples, dtype=np.float64)
    if f.ndim != 2 or f.shape[1] != 2 or len(f) < 2 or not np.all(np.isfinite(f)):
        raise ValueError("a stroke needs at least two finite 2D samples")
    keep = np.r_[True, np.linalg.norm(np.diff(f, axis=0), axis=1) > 1e-9]
    f = f[keep]
    if len(f) < 2:
        raise ValueError("a stroke needs two distinct samples")
    n = n or control_count(polyline_length(f), screen_width)
    a = basis(chord_parameters(f), n) * math.sqrt(w_fit / len(f))
    j = 64
    arc = max(polyline_length(f), 1e-9)  # d²/dσ² = d²/ds² / l², dσ = l ds
    c = basis(np.linspace(0.0, 1.0, j), n, order=2) * math.sqrt(w_curvature / j / arc**3)
    lhs = np.vstack([a, c])
    rhs = np.vstack([f * math.sqrt(w_fit / len(f)), np.zeros((j, 2))])
    q = np.linalg.lstsq(lhs, rhs, rcond=None)[0]
    return Hermite(np.asarray(q, dtype=np.float64))  # (lstsq's stubs say floating; it is float64 here)
