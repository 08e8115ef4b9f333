"""A pygame (SDL2) window with an OpenGL 3.3 core context, resizable, vsync if offered.

SDL is asked for a 3.3 core profile before the window opens; moderngl then wraps the
current context. ``poll_events`` hands the pygame events to the caller (the mouse input backend reads them) after handling the
two the window itself must know: resize and quit.

On a software rasteriser (no multisampling wanted) frames are drawn straight into the
window's own framebuffer. Drawing off-screen and copying the colour to the window cost
6.6 ms of CPU per 1280x720 frame on llvmpipe (the copy converts our BGRA texture to the
window's pixel format through the general blit path), a fifth of a 30 fps budget. A frame
that is to be read back (a screenshot) is asked for with :meth:`WindowTarget.keep_next_frame`
and drawn off-screen as before, because the window's back buffer is undefined once shown.
With multisampling (a GPU), every frame is drawn off-screen (:class:`~engine.render.offscreen.OffscreenBuffers`)
and blitted to the window in ``end()``, so anti-aliasing does not depend on the driver.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import moderngl
import numpy as np
from numpy.typing import NDArray

from engine.render.offscreen import OffscreenBuffers
from engine.render.target import save_image

__all__ = ["WindowTarget", "NoDisplayError"]

#: Tries of x11 by name after SDL fell back to an invisible driver, and the pause between them (s).
X11_ATTEMPTS, X11_PAUSE = 3, 0.3
#: SDL video drivers that open no visible window.
INVISIBLE_DRIVERS = ("dummy", "offscreen", "evdev")


class NoDisplayError(RuntimeError):
    """A window was asked for where there is no display to show it."""


def _open_display() -> None:
    """Start SDL's video; if it fell back to an invisible driver though X is there, ask for x11 by name.

    SDL picks its driver itself and, when X11 fails for a moment (an X server still starting,
    a bad ``XDG_RUNTIME_DIR``), quietly chooses ``offscreen``: a window nobody sees. Then x11
    is tried once explicitly; if that fails too, the error says what SDL said each time.
    """
    import os
    import time

    import pygame

    pygame.display.init()
    driver = pygame.display.get_driver()
    if driver not in INVISIBLE_DRIVERS:
        return
    first = pygame.get_error() or "no reason given"
    pygame.display.quit()
    explicit = os.environ.get("SDL_VIDEODRIVER", "").lower()
    retry = ""
    if os.environ.get("DISPLAY") and explicit != "x11":
        os.environ["SDL_VIDEODRIVER"] = "x11"
        try:
            for attempt in range(X11_ATTEMPTS):  # an X server still starting refuses for a moment
                try:
                    pygame.display.init()
                    return
                except pygame.error as exc:
                    retry = f"; x11 asked for explicitly, {attempt + 1} times: {exc}"
                    time.sleep(X11_PAUSE)
        finally:
            if explicit:
                os.environ["SDL_VIDEODRIVER"] = explicit
            else:
                del os.environ["SDL_VIDEODRIVER"]
    raise NoDisplayError(
        f"no display (SDL chose its {driver!r} video driver; SDL said: {first}{retry}): a window "
        "cannot be shown here; use --headless to run without one"
    )


class WindowTarget:
    """An on-screen target; ``closed`` turns true when the user closes the window."""

    def __init__(
        self, width: int, height: int, *, title: str = "PuppetPhone", samples: int | None = None, vsync: bool = True
    ) -> None:
        import pygame

        _open_display()
        gl = pygame
        pygame.display.gl_set_attribute(gl.GL_CONTEXT_MAJOR_VERSION, 3)
        pygame.display.gl_set_attribute(gl.GL_CONTEXT_MINOR_VERSION, 3)
        pygame.display.gl_set_attribute(gl.GL_CONTEXT_PROFILE_MASK, gl.GL_CONTEXT_PROFILE_CORE)
        pygame.display.gl_set_attribute(gl.GL_DEPTH_SIZE, 24)
        flags = pygame.OPENGL | pygame.DOUBLEBUF | pygame.RESIZABLE
        try:
            pygame.display.set_mode((width, height), flags, vsync=1 if vsync else 0)
        except pygame.error:
            # No vsync on this driver: a window without it beats no window.
            pygame.display.set_mode((width, height), flags)
        pygame.display.set_caption(title)
        self._pg = pygame
        self.ctx = moderngl.create_context(require=330)
        self.buffers = OffscreenBuffers(self.ctx, width, height, samples)
        self._screen = self.ctx.detect_framebuffer(0)
        self.straight = self.buffers.samples == 0 and pygame.display.gl_get_attribute(gl.GL_DEPTH_SIZE) >= 16
        """Frames are drawn into the window's framebuffer itself (no multisampling, and it has a depth buffer)."""
        self._keep = False
        self._offscreen = True
        """Whether the frame being drawn (or the last one) goes through :attr:`buffers`, so it can be read."""
        self.closed = False

    @property
    def size(self) -> tuple[int, int]:
        return self.buffers.size

    @property
    def framebuffer(self) -> moderngl.Framebuffer:
        return self._screen if self.straight and not self._keep else self.buffers.framebuffer

    def keep_next_frame(self) -> None:
        """Draw the next frame off-screen too, so that :meth:`read_pixels` can read it after ``end()``."""
        self._keep = True

    def begin(self) -> moderngl.Framebuffer:
        self._offscreen = not self.straight or self._keep
        if self._offscreen:
            return self.buffers.begin()
        self._screen.use()
        self._screen.viewport = (0, 0, *self.size)
        return self._screen

    def end(self) -> None:
        """Show the frame: one drawn off-screen is resolved and its colour copied to the window's
        framebuffer 0 first; then flip.

        Only colour is copied: a blit that includes depth fails with
        ``GL_INVALID_OPERATION`` when the window's depth format differs from ours (Mesa
        under X does), and the window never showed a pixel. The destination is named
        explicitly: ``detect_framebuffer()`` returns whatever is bound, which after
        drawing is our own buffer, so the frame was copied onto itself.
        """
        if self._offscreen:
            self.buffers.resolve()
            self.ctx.copy_framebuffer(self._screen, self.buffers.colour_only)
        self._keep = False
        self._pg.display.flip()

    def read_pixels(self) -> NDArray[np.uint8]:
        """The last frame, if it was drawn off-screen (after :meth:`keep_next_frame`, or with multisampling)."""
        if not self._offscreen:
            raise RuntimeError(
                "the last frame was drawn straight into the window, which cannot be read back once shown: "
                "call keep_next_frame() before drawing a frame to read"
            )
        return self.buffers.read_pixels()

    def screenshot(self, path: str | Path) -> Path:
        return save_image(self.read_pixels(), path)

    def poll_events(self) -> list[Any]:
        events = self._pg.event.get()
        for ev in events:
            if ev.type == self._pg.QUIT:
                self.closed = True
            elif ev.type in (self._pg.VIDEORESIZE, self._pg.WINDOWSIZECHANGED):
                w, h = self._pg.display.get_window_size()
                self.buffers.resize(max(int(w), 1), max(int(h), 1))
                self._screen = self.ctx.detect_framebuffer(0)  # the window's framebuffer at its new size
        return events

    def close(self) -> None:
        self.buffers.release()
        self.ctx.release()
        self._pg.display.quit()
        self.closed = True
