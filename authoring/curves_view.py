"""How the Motion Curves viewport is laid out: the panel's type size and a camera that frames the motion.

Issue 38 found the head cropped: the scene's camera was fixed for a standing puppet in a
large window. The camera is now fitted, in pixels, to the whole clip between the panel and
the key timeline, and the panel's type shrinks in a small window so its lines do not wrap
over the puppet.
"""

from __future__ import annotations

import numpy as np

from authoring.curves_timeline import Timeline
from engine.camera import OrbitCamera

__all__ = ["panel_layout", "framing_camera"]

from engine.arrays import F64 as F


def panel_layout(size: tuple[int, int]) -> tuple[int, int]:
    """``(font size, line step)`` of the panel: smaller in a small window, so its lines do not wrap over the puppet."""
    font = 18 if size[0] >= 1100 else 14 if size[0] >= 760 else 12
    return font, font + 8


def framing_camera(points: F, size: tuple[int, int], yaw: float = 1.1, pitch: float = 0.15) -> OrbitCamera:
    """A camera that shows every point of ``points [N,3]`` between the panel and the timeline.

    The points' bounding sphere is fitted, in pixels, into the band left free by the panel's
    four lines and the key timeline (and into the width), then the target is raised so the
    sphere's centre sits in the middle of that band rather than of the window.
    """
    cam = OrbitCamera(target=np.zeros(3), yaw=yaw, pitch=pitch, distance=1.0)
    lo, hi = points.min(axis=0), points.max(axis=0)
    centre = 0.5 * (lo + hi)
    radius = max(float(np.linalg.norm(hi - lo)) * 0.5, 0.3)
    w, h = size
    focal = 0.5 * h / np.tan(np.radians(cam.fov_y) * 0.5)  # pixels per unit of depth
    top = 10 + 4 * panel_layout(size)[1]
    bottom = Timeline(size, 2).top - 6
    half_band = max(0.5 * (bottom - top) - 4.0, 20.0)
    cam.distance = float(radius * focal / min(half_band, 0.5 * w - 8.0))
    rows_down = 0.5 * (top + bottom) - 0.5 * h  # how far below the window's middle the band's middle is
    cam.target = centre + np.array([0.0, rows_down * cam.distance / focal, 0.0])
    return cam
