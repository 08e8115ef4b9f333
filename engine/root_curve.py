"""The fitted curve of a looping clip's root position: closed cubic B-spline plus travel.

The cycle extractor fits the root's loop with a periodic cubic spline (SCA 2017 §4) and
MoCurves edits the root through the control points of such a spline (§5.1). Keeping that
one curve with the clip (``.ppclip`` stores it, see :mod:`engine.clipfile`) lets editing
start from the extracted control points instead of a second, different fit.

Keypoint ``k`` of an ``n``-frame loop sits at ``u = k/n`` of the closed uniform cubic
B-spline with ``K`` control points; a travelling loop (a walk) adds the straight ramp
``(k/n)·travel``, which is not periodic and so is not part of the spline::

    root[k] ≈ Σ_i B[k, i] · control[i] + (k/n) · travel

Only the root position has a curve here: rotations are edited in MoCurves with the per-keypoint
arrows, which have no control points to start from.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from engine.arrays import F64 as F

__all__ = ["RootCurve", "closed_basis"]


def closed_basis(n: int, k: int) -> F:
    """``[n,k]`` closed uniform cubic B-spline basis at ``n`` keypoints (partition of unity).

    Control point ``i``'s basis function peaks at keypoint ``i·n/k``.
    """
    if k < 4 or k > n:
        raise ValueError(f"need 4 ≤ control points ≤ keypoints, got {k} for {n}")
    u = np.arange(n) / n * k
    seg = np.floor(u).astype(np.int64)
    s = u - seg
    w = np.stack([(1 - s) ** 3, 3 * s**3 - 6 * s**2 + 4, -3 * s**3 + 3 * s**2 + 3 * s + 1, s**3], axis=1) / 6.0
    b = np.zeros((n, k))
    rows = np.arange(n)
    for m in range(4):
        np.add.at(b, (rows, (seg + m - 1) % k), w[:, m])
    return b


@dataclass(frozen=True)
class RootCurve:
    """Control points ``[K,3]`` of the root's closed spline and the per-cycle ``travel [3]`` (metres)."""

    control: F
    travel: F

    def __post_init__(self) -> None:
        c = np.array(self.control, dtype=np.float64)
        t = np.array(self.travel, dtype=np.float64)
        if c.ndim != 2 or c.shape[1] != 3 or c.shape[0] < 4 or t.shape != (3,):
            raise ValueError(f"a root curve needs control points [K≥4,3] and travel [3], got {c.shape} and {t.shape}")
        if not (np.isfinite(c).all() and np.isfinite(t).all()):
            raise ValueError("a root curve's control points and travel must be finite")
        c.setflags(write=False)
        t.setflags(write=False)
        object.__setattr__(self, "control", c)
        object.__setattr__(self, "travel", t)

    @property
    def count(self) -> int:
        """Number of control points ``K``."""
        return int(self.control.shape[0])

    def ramp(self, n: int) -> F:
        """``[n,3]`` the travel ramp ``(k/n)·travel`` at the keypoints."""
        return np.outer(np.arange(n) / n, self.travel)

    def positions(self, n: int) -> F:
        """``[n,3]`` the curve at the ``n`` keypoints of the loop."""
        return closed_basis(n, self.count) @ self.control + self.ramp(n)

    def shown(self) -> F:
        """``[K,3]`` where the control points are drawn: each moved by the ramp where its basis peaks."""
        return self.control + np.outer(np.arange(self.count) / self.count, self.travel)

    def moved(self, index: int, delta: ArrayLike) -> RootCurve:
        """The curve with control point ``index`` moved by ``delta``."""
        c = np.array(self.control)
        c[index] += np.asarray(delta, dtype=np.float64)
        return RootCurve(c, self.travel)

    def refit(self, positions: ArrayLike) -> RootCurve:
        """Least-squares control points (same ``K`` and travel) for new keypoint ``positions [n,3]``."""
        p = np.asarray(positions, dtype=np.float64)
        b = closed_basis(len(p), self.count)
        control = np.asarray(np.linalg.solve(b.T @ b, b.T @ (p - self.ramp(len(p)))), dtype=np.float64)
        return RootCurve(control, self.travel)
