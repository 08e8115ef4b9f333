"""Choosing the joint to drive by clicking the figure (``author record``), not only with ``--item``.

A press picks the joint whose bone passes nearest the cursor on screen, within
:data:`REACH_PX` pixels: each bone is the segment from a joint to its first child (a
leaf to its tip), so a click anywhere along the forearm picks the forearm.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from engine.camera import OrbitCamera

__all__ = ["joint_at", "REACH_PX"]

#: How far from a bone on screen a click still picks it.
REACH_PX = 24.0


def _segment_distance(p: NDArray[np.float64], a: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]:
    """Pixel distance of ``p [2]`` from each segment ``a[i]–b[i]`` (``[N,2]`` each)."""
    ab = b - a
    t = np.clip(np.einsum("ij,ij->i", p - a, ab) / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-12), 0.0, 1.0)
    return np.asarray(np.linalg.norm(a + t[:, None] * ab - p, axis=1))


def joint_at(
    camera: OrbitCamera,
    starts: NDArray[np.float64],
    ends: NDArray[np.float64],
    px: float,
    py: float,
    size: tuple[int, int],
) -> int | None:
    """The index of the bone (joint) nearest the cursor, or ``None`` when none is within reach.

    Args:
        starts, ends: ``[J,3]`` world positions of each joint and of its bone's end.
    """
    a = camera.project(starts, size[0], size[1])
    b = camera.project(ends, size[0], size[1])
    d = _segment_distance(np.array([px, py], dtype=np.float64), a, b)
    d[~np.isfinite(d)] = np.inf
    best = int(np.argmin(d))
    return best if d[best] <= REACH_PX else None
