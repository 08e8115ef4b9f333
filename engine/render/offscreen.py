"""Off-screen colour+depth buffers, multisampled, resolved for read-back.

Both targets draw into these: the headless target reads them back, the window target
also blits them to the screen. Drawing off-screen in the window too means every target
gets the same anti-aliasing whatever the driver's default framebuffer offers, and a
screenshot after ``end()`` reads a defined buffer (a window's back buffer is undefined
after the swap).
"""

from __future__ import annotations

from pathlib import Path

import moderngl
import numpy as np
from numpy.typing import NDArray

from engine.render.bgra import colour_texture, release_texture
from engine.render.target import save_image

__all__ = ["OffscreenBuffers", "is_software"]


def is_software(ctx: moderngl.Context) -> bool:
    """Whether the context renders on the CPU (Mesa llvmpipe/softpipe, SwiftShader)."""
    name = str(ctx.info.get("GL_RENDERER", "")).lower()
    return any(s in name for s in ("llvmpipe", "softpipe", "swiftshader", "software"))


class OffscreenBuffers:
    """A ``width`` x ``height`` RGBA8 + depth framebuffer with optional MSAA.

    Its resolved colour is a texture (:func:`~engine.render.bgra.colour_texture`), not a renderbuffer.

    ``samples=None`` picks 4x MSAA on a GPU and none on a software rasteriser, where
    multisampling multiplies the frame cost (measured: 4x MSAA quadrupled it on llvmpipe).
    """

    def __init__(self, ctx: moderngl.Context, width: int, height: int, samples: int | None = None) -> None:
        self.ctx = ctx
        if samples is None:
            samples = 0 if is_software(ctx) else 4
        self.samples = min(samples, ctx.max_samples) if samples > 1 else 0
        self._msaa: moderngl.Framebuffer | None = None
        self._make(width, height)

    def _make(self, width: int, height: int) -> None:
        size = (width, height)
        ctx = self.ctx
        # A colour texture stored as BGRA on a software rasteriser: the scale-up of quality low
        # and medium can then take llvmpipe's fast copying path (see engine.render.bgra).
        self.resolved = ctx.framebuffer(
            color_attachments=[colour_texture(ctx, size, is_software(ctx))],
            depth_attachment=ctx.depth_renderbuffer(size),
        )
        # The same colour renderbuffer without depth: what a window presents (a blit to
        # the default framebuffer must not include depth, whose format may differ).
        self.colour_only = ctx.framebuffer(color_attachments=[self.resolved.color_attachments[0]])
        self._msaa = None
        if self.samples:
            self._msaa = ctx.framebuffer(
                color_attachments=[ctx.renderbuffer(size, 4, samples=self.samples)],
                depth_attachment=ctx.depth_renderbuffer(size, samples=self.samples),
            )
        self.size = size

    @property
    def framebuffer(self) -> moderngl.Framebuffer:
        """Where a frame is drawn (the multisampled buffer when there is one)."""
        return self._msaa if self._msaa is not None else self.resolved

    def resize(self, width: int, height: int) -> None:
        """Reallocate for a new size (contents are lost)."""
        if width <= 0 or height <= 0:
            raise ValueError(f"size must be positive, got {width}x{height}")
        if (width, height) != self.size:
            self.release()
            self._make(width, height)

    def begin(self) -> moderngl.Framebuffer:
        """Bind the drawing framebuffer with a full viewport and return it."""
        fb = self.framebuffer
        fb.use()
        fb.viewport = (0, 0, *self.size)
        return fb

    def resolve(self) -> None:
        """Resolve multisampling into :attr:`resolved` (no-op without MSAA)."""
        if self._msaa is not None:
            self.ctx.copy_framebuffer(self.resolved, self._msaa)

    def read_pixels(self) -> NDArray[np.uint8]:
        """The resolved image as ``[H,W,3]`` uint8, top row first."""
        w, h = self.size
        raw = self.resolved.read(components=3, alignment=1)
        return np.frombuffer(raw, dtype=np.uint8).reshape(h, w, 3)[::-1].copy()

    def screenshot(self, path: str | Path) -> Path:
        """Save the resolved image (PNG or JPEG by suffix)."""
        return save_image(self.read_pixels(), path)

    def release(self) -> None:
        """Free the GPU buffers."""
        self.colour_only.release()
        for fb in (self.resolved, self._msaa):
            if fb is not None:
                for att in (*fb.color_attachments, fb.depth_attachment):
                    if isinstance(att, moderngl.Texture):
                        release_texture(att)
                    elif att is not None:
                        att.release()
                fb.release()
        self._msaa = None
