"""Geometry the MotionStick needs: ray picking and stick shortening, vectorised over targets.

Kept apart from the system so the maths can be tested on plain arrays.
"""

from __future__ import annotations

import numpy as np

__all__ = ["pick", "pick_capsules", "shorten"]

from engine.arrays import F64 as F
from engine.arrays import Bool


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
    return _nearest(t, (d2 <= r2) & (t >= 0.0) & (t <= max_distance))


def pick_capsules(
    origin: F, direction: F, a: F, b: F, radii: F, max_distance: float = 50.0
) -> tuple[int, float] | None:
    """First capsule (segment ``a[i]``–``b[i]`` swept by ``radii[i]``) hit by the ray ``origin + t·direction``.

    Returns ``(index, t)`` of the nearest hit in front of the origin within ``max_distance``, or
    ``None``. ``t`` is where the ray enters the ball around the segment point nearest the ray: exact
    for a hit on a cap or square onto the side, a little deeper for a glancing hit along the side
    (the capsule is the union of those balls). Picking asks which body part is first, and this
    orders them as the eye does. A ray starting inside a capsule hits it at ``t = 0``.
    """
    if len(a) == 0:
        return None
    d = np.asarray(direction, dtype=np.float64)
    u = b - a
    w = a - origin
    uu = np.einsum("ij,ij->i", u, u)
    ud = u @ d
    uw = np.einsum("ij,ij->i", u, w)
    wd = w @ d
    # Closest points of the line o + t·d and the segment a + s·u (|d| = 1): minimise over s in [0, 1]
    # with t = (w + s·u)·d, which is |w + s·u|² − ((w + s·u)·d)², a quadratic in s.
    denom = uu - ud * ud
    safe = np.where(denom > 1e-12, denom, 1.0)
    # Parallel (or a point): every s is as near; the end met first along the ray is the one the eye sees.
    s = np.where(denom > 1e-12, (ud * wd - uw) / safe, np.where(ud < 0.0, 1.0, 0.0))
    s = np.clip(s, 0.0, 1.0)
    point = a + s[:, None] * u
    t_near = (point - origin) @ d
    gap = point - (origin + t_near[:, None] * d)
    d2 = np.where(t_near >= 0.0, np.einsum("ij,ij->i", gap, gap), np.inf)  # nearest behind: no hit ahead
    r2 = radii * radii
    # The origin inside the capsule: its distance to the segment's point nearest to it.
    s0 = np.clip(-uw / np.where(uu > 1e-12, uu, 1.0), 0.0, 1.0)
    oc = w + s0[:, None] * u
    inside = np.einsum("ij,ij->i", oc, oc) <= r2
    t = np.where(inside, 0.0, t_near - np.sqrt(np.maximum(r2 - np.where(np.isfinite(d2), d2, 0.0), 0.0)))
    d2 = np.where(inside, 0.0, d2)
    return _nearest(t, (d2 <= r2) & (t >= 0.0) & (t <= max_distance))


def _nearest(t: F, valid: Bool) -> tuple[int, float] | None:
    """``(index, t)`` of the smallest valid ``t``, or ``None``: the hit a ray meets first."""
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
