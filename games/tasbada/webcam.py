"""The real world through a webcam (pygame.camera: V4L2 on Linux), or a clear word why not.

Only the view uses the camera — the live backdrop of stage 1 until the first mark
freezes it, and the selfie — never the simulation, so a session replays the same with
or without one. :func:`open_camera` returns ``(camera or None, message)``; the message
says which camera is used, or that none was found, or that it is busy, and which
photo stands in for it.
"""

from __future__ import annotations

import os
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["Webcam", "open_camera"]


class Webcam:
    """A started pygame camera; :meth:`frame` returns the latest picture as ``[H,W,3]`` uint8."""

    def __init__(self, cam: Any, name: str) -> None:
        self._cam = cam
        self.name = name
        self._last: NDArray[np.uint8] | None = None

    def frame(self) -> NDArray[np.uint8] | None:
        """The newest frame (the previous one if none is ready; ``None`` before the first)."""
        import pygame

        try:
            if self._last is None or self._cam.query_image():
                surf = self._cam.get_image()
                self._last = np.ascontiguousarray(pygame.surfarray.array3d(surf).swapaxes(0, 1))
        except (pygame.error, SystemError, OSError):
            pass
        return self._last

    def close(self) -> None:
        """Stop the camera (free it for other programs)."""
        try:
            self._cam.stop()
        except Exception:  # already stopped or unplugged: nothing left to free
            pass


def open_camera(photo_label: str) -> tuple[Webcam | None, str]:
    """The first webcam, started; or ``None`` and a message naming the stand-in photo.

    ``$TASBADA_CAMERA`` picks a device (``/dev/video2``) or, set to ``none``, skips the camera.
    """
    choice = os.environ.get("TASBADA_CAMERA", "")
    if choice.lower() in ("none", "off", "0"):
        return None, f"camera off (TASBADA_CAMERA={choice}); using the photo {photo_label}"
    try:
        import pygame
        import pygame.camera
    except ImportError as exc:
        return None, f"no camera support ({exc}); using the photo {photo_label}"
    try:
        pygame.camera.init()
        names = pygame.camera.list_cameras()
    except Exception as exc:  # backends raise assorted errors when no video stack exists
        return None, f"no camera found ({exc}); using the photo {photo_label}"
    if choice:
        names = [choice]
    if not names:
        return None, f"no camera found; using the photo {photo_label}"
    name = names[0]
    try:
        cam = pygame.camera.Camera(name, (640, 480))
        cam.start()
    except Exception as exc:
        return None, f"camera {name} is busy or cannot start ({exc}); using the photo {photo_label}"
    return Webcam(cam, str(name)), f"camera: {name} (live until you mark the first object)"
