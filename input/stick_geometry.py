"""Geometry the MotionStick needs: ray picking and stick shortening, vectorised over targets.

Kept apart from the system so the maths can be tested on plain arrays.
"""

from __future__ import annotations

import numpy as np

__all__ = ["pick", "shorten"]

from engine.arrays import F64 as F


def pick(origin: F, direction: F, centers: F, radii: F, max_distance: float = 50.0) -> tuple[int, float] | None:
    """First sphere hit by the ray ``origin + t·direction`` (``direction`` unit).

    Returns ``(index, t)`` of the nearest hit in front of the origin within
    ``max_distance``, or ``None``. A ray starting inside a sphere hits it at ``t = 0``.
    """
    if len(centers) == 0:
        return None
    oc = centers - origin
    tca = oc @ direction
    d2 = np.einsum("ij,ij->i", oc, oc) - tca * tca
    r2 = radii * radii
    inside = np.einsum("ij,ij->i", oc, oc) <= r2
    thc = np.sqrt(np.maximum(r2 - d2, 0.0))
    t = np.where(inside, 0.0, tca - thc)
    valid = (d2 <= r2) & (t >= 0.0) & (t <= max_distance)
    if not np.any(valid):
        return None
    t = np.where(valid, t, np.inf)
    i = int(np.argmin(t))
    return i, float(t[i])


def shorten(
    pivot: F,
    direction: F,
    length: float,
    ground_y: float = 0.0,
    bases: F | None = None,
    radii: F | None = None,
    heights: F | None = None,
) -> float:
    """The stick length allowed before the tip would go below the ground or into an obstacle.

    Obstacles are vertical cylinders standing on ``bases [N,3]`` with ``radii`` and
    ``heights``. The result is in ``[0, length]``.
    """
    limit = length
    if direction[1] < -1e-12:
        limit = min(limit, max(0.0, (ground_y - pivot[1]) / direction[1]))
    elif pivot[1] < ground_y:
        return 0.0
    if bases is None or radii is None or heights is None or len(bases) == 0:
        return limit
    # Side walls: |(p + t d - c)_xz| = r.
    oc = pivot[[0, 2]] - bases[:, [0, 2]]
    dxz = direction[[0, 2]]
    a = float(dxz @ dxz)
    b = 2.0 * (oc @ dxz)
    c = np.einsum("ij,ij->i", oc, oc) - radii * radii
    hits = np.full(len(bases), np.inf)
    if a > 1e-12:
        disc = b * b - 4.0 * a * c
        ok = disc >= 0.0
        t_side = (-b - np.sqrt(np.where(ok, disc, 0.0))) / (2.0 * a)
        y = pivot[1] + t_side * direction[1]
        ok &= (t_side >= 0.0) & (y >= bases[:, 1]) & (y <= bases[:, 1] + heights)
        hits = np.where(ok, t_side, hits)
    # Top caps, for a stick coming down from above.
    if direction[1] < -1e-12:
        t_top = (bases[:, 1] + heights - pivot[1]) / direction[1]
        p = pivot[None, [0, 2]] + t_top[:, None] * dxz[None, :] - bases[:, [0, 2]]
        ok = (t_top >= 0.0) & (np.einsum("ij,ij->i", p, p) <= radii * radii)
        hits = np.minimum(hits, np.where(ok, t_top, np.inf))
    # A pivot already inside an obstacle does not stop the stick (it could never move out).
    inside = (c <= 0.0) & (pivot[1] >= bases[:, 1]) & (pivot[1] <= bases[:, 1] + heights)
    hits = np.where(inside, np.inf, hits)
    return float(min(limit, hits.min()))
