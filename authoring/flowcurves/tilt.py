"""How far an object's base turned: the limit that keeps a stroke from toppling a planted object.

A stroke bends what stands near it, and the ARAP solve follows it as far as the shape
constraints ask: a long stroke drawn sideways can lay a tree flat, pivoting it on the two
points that hold it to the ground. A planted object may bend, not fall: the rotation of its
**base** — the lowest third of its height, fitted rigidly (Kabsch) from rest to bent — must
stay within :data:`MAX_BASE_TILT_DEG`. :class:`~authoring.flowcurves.deform.SceneDeformer`
enforces it by following the stroke only part of the way when the whole way would tilt a
base further (the largest such part, by bisection).
"""

from __future__ import annotations

import numpy as np

__all__ = ["BASE_FRACTION", "MAX_BASE_TILT_DEG", "base_tilt_deg"]

from engine.arrays import F64 as F

MAX_BASE_TILT_DEG = 25.0
#: The base is this lowest fraction of the object's height.
BASE_FRACTION = 1.0 / 3.0


def base_tilt_deg(rest: F, bent: F, up: F, fraction: float = BASE_FRACTION) -> float:
    """Rotation (degrees) of the best rigid fit of the lowest ``fraction`` of points (along ``up``).

    Works in 2D (screen points, ``up = (0, -1)``) and 3D (world points, ``up = (0, 1, 0)``).
    """
    rest, bent = np.asarray(rest, dtype=np.float64), np.asarray(bent, dtype=np.float64)
    h = rest @ np.asarray(up, dtype=np.float64)
    base = h <= h.min() + fraction * (h.max() - h.min())
    if base.sum() < 2:
        return 0.0
    a = rest[base] - rest[base].mean(axis=0)
    b = bent[base] - bent[base].mean(axis=0)
    u, _, vt = np.linalg.svd(a.T @ b)
    r = (u @ vt).T
    if np.linalg.det(r) < 0:  # a reflection is not a rotation: flip the weakest axis
        vt[-1] *= -1
        r = (u @ vt).T
    if r.shape == (2, 2):
        return float(abs(np.degrees(np.arctan2(r[1, 0], r[0, 0]))))
    return float(np.degrees(np.arccos(np.clip((np.trace(r) - 1.0) / 2.0, -1.0, 1.0))))
