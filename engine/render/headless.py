"""Off-screen rendering on an EGL standalone context (no display needed).

Used by ``--headless`` runs, screenshots in CI and the GL tests. Mesa's llvmpipe
provides OpenGL 3.3 core here.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import moderngl
import numpy as np
from numpy.typing import NDArray

from engine.render.offscreen import OffscreenBuffers

__all__ = ["HeadlessTarget", "egl_available"]


def _egl_context() -> moderngl.Context:
    """A standalone GL 3.3 context on EGL (the one place that names the backend)."""
    return moderngl.create_standalone_context(
        backend="egl",  # type: ignore[arg-type]  # moderngl's stubs type each **settings value as a dict; backend is a str
        require=330,
    )


def egl_available() -> str | None:
    """``None`` if an EGL GL 3.3 context can be created here, else the reason it cannot."""
    try:
        ctx = _egl_context()
    except Exception as exc:  # any failure means "no headless GL here"; the message says why
        return f"{type(exc).__name__}: {exc}"
    ctx.release()
    return None


class HeadlessTarget:
    """An off-screen ``width`` x ``height`` target; pass ``ctx`` to share an existing context."""

    def __init__(
        self, width: int, height: int, *, samples: int | None = None, ctx: moderngl.Context | None = None
    ) -> None:
        self.ctx = ctx if ctx is not None else _egl_context()
        self._own_ctx = ctx is None
        self.buffers = OffscreenBuffers(self.ctx, width, height, samples)

    @property
    def size(self) -> tuple[int, int]:
        return self.buffers.size

    @property
    def framebuffer(self) -> moderngl.Framebuffer:
        return self.buffers.framebuffer

    def resize(self, width: int, height: int) -> None:
        """Change the image size."""
        self.buffers.resize(width, height)

    def begin(self) -> moderngl.Framebuffer:
        return self.buffers.begin()

    def end(self) -> None:
        self.buffers.resolve()

    def keep_next_frame(self) -> None:
        """Nothing to do: every frame drawn here can be read back."""

    def read_pixels(self) -> NDArray[np.uint8]:
        return self.buffers.read_pixels()

    def screenshot(self, path: str | Path) -> Path:
        return self.buffers.screenshot(path)

    def poll_events(self) -> list[Any]:
        return []

    def close(self) -> None:
        self.buffers.release()
        if self._own_ctx:
            self.ctx.release()
