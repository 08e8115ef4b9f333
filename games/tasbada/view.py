"""Where the photo and the 3-D world meet: the game camera, the pointer, the floor.

The photo is drawn behind the world in screen space (``RenderScene.background``), so a
pixel of the photo and a pixel of the view coincide when the viewport has the photo's
16:9 aspect (the default 1280x720 window; other aspects crop the photo). Everything
the quest knows about the image is in *normalised image coordinates* ``(u, v)``:
``u`` from 0 at the left to 1 at the right, ``v`` from 0 at the top to 1 at the bottom,
independent of the photo's resolution.

The pointer is the MotionStick's tip seen by the game camera: with the mouse the tip
lies on the ray under the cursor, so it projects exactly to the cursor; with a phone
it is where the phone points, so aiming the phone moves the pointer over the photo.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from engine.camera import OrbitCamera

__all__ = ["ASPECT", "game_camera", "to_image", "floor_point", "floor_depth", "QUEST_HALF_WIDTH"]

ASPECT = 16.0 / 9.0
"""The aspect the photo is cropped to and the image mapping assumes."""
QUEST_HALF_WIDTH = 3.0
"""Half the width (metres, along X) of the floor the quest uses."""

_CAMERA = OrbitCamera(target=np.array([0.0, 0.7, 0.0]), yaw=0.0, pitch=0.22, distance=7.0, fov_y=50.0)
_W, _H = 1600, 900  # any 16:9 pair: the mapping only uses their ratio


def game_camera() -> OrbitCamera:
    """A fresh copy of the camera the photo is lined up with."""
    c = _CAMERA
    return OrbitCamera(target=c.target.copy(), yaw=c.yaw, pitch=c.pitch, distance=c.distance, fov_y=c.fov_y)


def to_image(points: ArrayLike) -> NDArray[np.float64]:
    """Normalised image coordinates ``[N,2]`` of world points ``[N,3]`` (NaN behind the camera)."""
    px = _CAMERA.project(points, _W, _H)
    return px / np.array([_W, _H])


def floor_point(u: float, v: float) -> NDArray[np.float64] | None:
    """The floor point (y = 0) seen at image ``(u, v)``; ``None`` at or above the horizon."""
    origin, direction = _CAMERA.ray(u * _W, v * _H, _W, _H)
    if direction[1] > -1e-3:
        return None
    t = -origin[1] / direction[1]
    return origin + t * direction


def floor_depth(v: float, far: float = -8.0) -> float:
    """World Z of the floor seen at image row ``v`` (centre column), clamped to ``far`` near the horizon."""
    p = floor_point(0.5, v)
    return far if p is None else float(max(p[2], far))
