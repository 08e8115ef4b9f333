"""Spline fitting (paper §4): one looping cubic Bézier curve per component of each item.

The paper fits a cubic Bézier spline per component (translation ``γ_P``, rotation ``γ_R``,
scale ``γ_S``) with Maya's fitter; MoCurves then edit those control points. Here the
fit is a least-squares *periodic* uniform cubic B-spline, converted exactly to Bézier
segments: periodic so the loop stays closed and C² across the seam, least squares so
performance noise is smoothed instead of interpolated. The number of segments
starts at four and grows until the worst sample is within the error bound (or every
sample has its own segment, which interpolates).

Rotations are fitted in the tangent space at their mean, ``r(t) = log(q̄⁻¹ q(t))``, and
evaluated back with ``q̄ · exp(r)``; the bound is an angle in radians. Vector items
use a bound relative to their peak-to-peak range.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from authoring.cycles.stitch import rotation_angle
from authoring.cycles.trajectory import Item
from engine import quat

__all__ = ["DEFAULT_ANGLE_TOLERANCE", "DEFAULT_TOLERANCE", "BezierLoop", "fit_item"]

DEFAULT_TOLERANCE = 0.01  # share of the item's range
DEFAULT_ANGLE_TOLERANCE = 0.01  # radians, about 0.6°

# Uniform cubic B-spline segment -> Bézier control points (rows: b0..b3, columns: P0..P3).
_TO_BEZIER = np.array([[1, 4, 1, 0], [0, 4, 2, 0], [0, 2, 4, 0], [0, 1, 4, 1]], dtype=np.float64) / 6.0


@dataclass(frozen=True)
class BezierLoop:
    """A closed piecewise cubic Bézier curve over one period.

    Attributes:
        name: item name.
        kind: item kind.
        period: loop length in seconds.
        control: ``[K, 4, d]`` Bézier control points of the K segments (tangent space for rotations).
        reference: the mean quaternion a rotation curve is expressed around (None otherwise).
        max_error: worst deviation from the fitted samples (item units, radians for rotations).
    """

    name: str
    kind: str
    period: float
    control: NDArray[np.float64]
    reference: NDArray[np.float64] | None
    max_error: float

    @property
    def segments(self) -> int:
        """Number of Bézier segments ``K``."""
        return int(self.control.shape[0])

    def closed_control(self) -> NDArray[np.float64]:
        """``[K, d]`` the periodic B-spline control points the Bézier segments came from.

        Indexed as :func:`engine.root_curve.closed_basis` (MoCurves' control points): segment
        ``k``'s inner Bézier points are ``(2c + c')/3`` and ``(c + 2c')/3`` of two consecutive
        control points, so ``c = 2·b1 − b2`` recovers them exactly.
        """
        return 2.0 * self.control[:, 1, :] - self.control[:, 2, :]

    def evaluate(self, t: NDArray[np.float64] | float) -> NDArray[np.float64]:
        """Values at times ``t`` (wrapped into the period): ``[..., d]`` or quaternions ``[..., 4]``."""
        u = np.mod(np.asarray(t, dtype=np.float64) / self.period, 1.0) * self.segments
        seg = np.minimum(np.floor(u).astype(np.int64), self.segments - 1)
        s = (u - seg)[..., None]
        b = self.control[seg]
        one = 1.0 - s
        v = one**3 * b[..., 0, :] + 3 * one**2 * s * b[..., 1, :] + 3 * one * s**2 * b[..., 2, :] + s**3 * b[..., 3, :]
        if self.kind == "rotation" and self.reference is not None:
            return quat.normalize(quat.mul(self.reference, quat.exp(v)))
        return v


def _basis(samples: int, segments: int) -> NDArray[np.float64]:
    """``[samples, segments]`` periodic uniform cubic B-spline basis at ``s/samples`` of the loop."""
    u = np.arange(samples) / samples * segments
    seg = np.floor(u).astype(np.int64)
    s = u - seg
    w = np.stack([(1 - s) ** 3, 3 * s**3 - 6 * s**2 + 4, -3 * s**3 + 3 * s**2 + 3 * s + 1, s**3], axis=1) / 6.0
    b = np.zeros((samples, segments))
    rows = np.arange(samples)
    for k in range(4):
        np.add.at(b, (rows, (seg + k) % segments), w[:, k])
    return b


def _fit(values: NDArray[np.float64], segments: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Least-squares control points and Bézier segments ``[K,4,d]`` for samples over one period."""
    b = _basis(len(values), segments)
    # Normal equations: B is tiny (segments ≤ samples) and well conditioned for a uniform
    # periodic basis, and solving K×K beats an SVD of the data by far when d is large.
    ctrl = np.asarray(np.linalg.solve(b.T @ b, b.T @ values), dtype=np.float64)
    idx = (np.arange(segments)[:, None] + np.arange(4)[None, :]) % segments
    bez = np.einsum("ij,kjd->kid", _TO_BEZIER, ctrl[idx])
    return ctrl, bez


def fit_item(item: Item, loop: NDArray[np.float64], period: float, tolerance: float | None = None) -> BezierLoop:
    """Fit one item's closed loop (``[S, d]`` samples at ``s·T/S``, the end not repeated) within the bound."""
    samples = len(loop)
    if samples < 4:
        raise ValueError(f"item {item.name!r}: a loop needs at least 4 samples to fit, got {samples}")
    reference = None
    if item.kind == "rotation":
        reference = quat.normalize(loop.sum(axis=0))
        data = quat.log(quat.mul(quat.conjugate(reference)[None], loop))
        bound = DEFAULT_ANGLE_TOLERANCE if tolerance is None else tolerance
    else:
        data = loop
        span = float(np.max(np.ptp(loop, axis=0))) if samples else 0.0
        bound = (DEFAULT_TOLERANCE if tolerance is None else tolerance) * max(span, 1e-12)
    t = np.arange(samples) / samples * period
    segments = min(4, samples)
    while True:
        _, bez = _fit(data, segments)
        curve = BezierLoop(item.name, item.kind, period, bez, reference, 0.0)
        fitted = curve.evaluate(t)
        if item.kind == "rotation":
            err = rotation_angle(fitted, loop)
        else:
            err = float(np.max(np.abs(fitted - loop))) if samples else 0.0
        if err <= bound or segments >= samples:
            return BezierLoop(item.name, item.kind, period, bez, reference, err)
        segments = min(samples, max(segments + 1, round(segments * 1.5)))
