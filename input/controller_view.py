"""The controller as the camera (thesis prototype): render the scene from the held phone's pose.

A device-mode stick (web page, OSC phone, SpaceMouse, serial IMU) sits at its pivot —
the virtual phone, moved by the tracked position of 6-DoF controllers — and points
along the stick. Seen as a camera it looks along the stick with the screen normal
up, which for a phone held like a camera (WebXR, ARKit) is exactly its back camera's
pose: ``input.phone_frames.arkit_to_stick`` added a half turn about Y, and this takes
it away again. The mouse's stick is held at the view's own eye, so it has no view of
its own: ``None`` there, and the caller keeps its orbit camera.
"""

from __future__ import annotations

import numpy as np

from engine import quat
from engine.camera import PhoneCamera
from engine.components import Stick
from engine.ecs import World
from input.motionstick import StickState

__all__ = ["controller_camera", "FOV_Y"]

#: A phone's main camera, portrait, is about 60° vertically; the game window is landscape.
FOV_Y = 60.0
_HALF_TURN_Y = quat.from_axis_angle([0.0, 1.0, 0.0], np.pi)


def controller_camera(world: World) -> PhoneCamera | None:
    """The view from the first controller that drives a stick in device mode, or ``None``."""
    for _, stick, st in world.query(Stick, StickState):
        if st.source and stick.connected and not st.world_mode:
            return PhoneCamera(
                position=stick.pivot.copy(), orientation=quat.mul(stick.orientation, _HALF_TURN_Y), fov_y=FOV_Y
            )
    return None
