"""``Viewer``: a target, a renderer and a camera, what the runner draws through.

The frame loop itself is :class:`engine.runner.Runner`'s; the viewer is the same with or
without a display (a window or an EGL off-screen target), so the loop does not care.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from engine.camera import Camera, OrbitCamera
from engine.render.renderer import Renderer
from engine.render.scene import RenderScene
from engine.render.target import RenderTarget, make_target

__all__ = ["Viewer"]


class Viewer:
    """Draws scenes into a target through ``camera`` (an :class:`OrbitCamera` by default)."""

    def __init__(self, target: RenderTarget, camera: Camera | None = None, renderer: Renderer | None = None) -> None:
        self.target = target
        self.camera: Camera = camera if camera is not None else OrbitCamera()
        self.renderer = renderer if renderer is not None else Renderer(target.ctx)

    @classmethod
    def create(cls, headless: bool, width: int = 1280, height: int = 720, **target_options: Any) -> Viewer:
        """A viewer on a new window or headless target (options go to :func:`make_target`)."""
        return cls(make_target(headless, width, height, **target_options))

    @property
    def size(self) -> tuple[int, int]:
        """Target size in pixels."""
        return self.target.size

    def draw(self, scene: RenderScene) -> None:
        """Render one frame of ``scene`` and present (or resolve) it.

        The target's context is made current first: another context created (and
        released) since, by a second viewer or a probe, would otherwise receive the
        GL calls, or none would, and the frame would be garbage.
        """
        with self.target.ctx:
            fb = self.target.begin()
            self.renderer.render(scene, self.camera, fb)
            self.target.end()

    def poll_events(self) -> list[Any]:
        """Window events since the last call (empty when headless)."""
        return self.target.poll_events()

    def keep_next_frame(self) -> None:
        """Make the next :meth:`draw` readable by :meth:`read_pixels` and :meth:`screenshot` (see the target's)."""
        self.target.keep_next_frame()

    def read_pixels(self) -> NDArray[np.uint8]:
        """The last drawn frame, ``[H,W,3]`` uint8."""
        with self.target.ctx:
            return self.target.read_pixels()

    def screenshot(self, path: str | Path) -> Path:
        """Save the last drawn frame as PNG."""
        with self.target.ctx:
            return self.target.screenshot(path)

    def close(self) -> None:
        """Free the renderer and the target."""
        self.renderer.release()
        self.target.close()
