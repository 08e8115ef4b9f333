"""Mouse to scene for the editors: the point under the pointer, and which drawn point it is on.

MoCurves (:mod:`authoring.edit_scene`) and Motion Curves (:mod:`authoring.curves_scene`)
both drag points of 3-D curves with a 2-D mouse; they share these so a drag means the
same thing, to the pixel, in both.
"""

from __future__ import annotations

import numpy as np

from engine.camera import Camera

__all__ = ["PICK_PX", "point_on_view_plane", "pick_point"]

from engine.arrays import F64 as F

PICK_PX = 14.0  # how close (pixels) the pointer must be to a drawn point to take it


def point_on_view_plane(camera: Camera, size: tuple[int, int], px: tuple[float, float], through: F) -> F:
    """The point under pixel ``px`` on the plane through ``through`` facing the camera."""
    origin, d = camera.ray(px[0], px[1], *size)
    n = camera.forward
    t = float(np.dot(through - origin, n) / max(np.dot(d, n), 1e-9))
    return origin + t * d


def pick_point(camera: Camera, size: tuple[int, int], points: F, px: tuple[float, float]) -> int | None:
    """Index of the point of ``points [N,3]`` drawn nearest ``px``, if within :data:`PICK_PX`; else ``None``."""
    screen = camera.project(points, *size)
    dist = np.linalg.norm(screen - np.asarray(px), axis=1)
    dist = np.where(np.isnan(dist), np.inf, dist)
    k = int(np.argmin(dist))
    return k if dist[k] <= PICK_PX else None
