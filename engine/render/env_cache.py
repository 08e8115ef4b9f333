"""The sky and the ground of a still view, drawn once and copied into each frame after.

A frame's sky and ground depend only on the view (camera, sun, fog, colours, the ground's
settings), not on what stands in the scene: the decals that do (shadow, track, footprints)
are drawn over them afterwards. Games like the snowman field keep the camera still, so
every frame drew the same ground again: on llvmpipe its clear and mesh cost 0.6 + 2-3 ms of
a 640x360 buffer at quality ``low``. Instead the first frame of a view clears, draws sky
and ground, and copies the buffer's colour and depth here; the next frames of the same
view copy them back in place of the clear (``glBlitFramebuffer`` between buffers of one
size and format, which llvmpipe does as a memory copy: 0.14 ms at 640x360, where the clear
alone cost 0.59 ms). The objects are then drawn over that ground, tested against its depth.

The key is a digest of everything the sky and ground programs read (:func:`view_key`); a
new key (the camera moved, the sun turned, the quality changed the buffer's size) draws and
copies again. Cost on a changing view: one copy more per frame, and the ground is shaded
under the objects too (it was drawn after them, behind the early depth test).
"""

from __future__ import annotations

import hashlib
from collections.abc import Iterable, Mapping

import moderngl
import numpy as np

from engine.render.bgra import colour_texture, release_texture
from engine.render.rawgl import COLOR_BUFFER_BIT, DEPTH_BUFFER_BIT, blit

__all__ = ["EnvironmentCache", "view_key", "single_sampled"]

_BOTH = COLOR_BUFFER_BIT | DEPTH_BUFFER_BIT


def view_key(flags: object, names: Iterable[str], values: Mapping[str, object]) -> bytes:
    """A digest of ``flags`` (the variant, size and switches, by ``repr``) and of the values of the
    uniforms ``names`` (those the sky and ground programs read; a name without a value counts as
    unset: it is a constant the draw sets itself)."""
    h = hashlib.blake2b(repr(flags).encode(), digest_size=16)
    for name in names:
        value = values.get(name)
        h.update(name.encode())
        h.update(b"-" if value is None else np.asarray(value, dtype=np.float64).tobytes())
    return h.digest()


def single_sampled(framebuffer: moderngl.Framebuffer) -> bool:
    """Whether ``framebuffer`` has attachments and none is multisampled (a copy into it can work).

    A framebuffer moderngl detected rather than made (a window's own, drawn into straight) lists no
    attachments: their formats and samples are unknown, so nothing is copied into it and its sky and
    ground are drawn each frame."""
    colour = framebuffer.color_attachments
    if not colour:
        return False
    return all(a is None or a.samples == 0 for a in [*colour, framebuffer.depth_attachment])


class EnvironmentCache:
    """One view's colour and depth, kept for copying back (see the module docstring).

    Args:
        ctx: the renderer's context.
        bgra: store the colour as BGRA (on a software rasteriser, to match the buffers drawn into).
    """

    def __init__(self, ctx: moderngl.Context, bgra: bool) -> None:
        self.ctx, self.bgra = ctx, bgra
        self._fbo: moderngl.Framebuffer | None = None
        self.key: bytes | None = None
        """The view the copy holds (``None``: nothing usable)."""
        self.stores = 0
        """How many times a view was copied in (tests count redraws with it)."""

    def restore(self, key: bytes, target: moderngl.Framebuffer) -> bool:
        """Copy the kept view into ``target`` if it is ``key``'s; false (nothing copied) otherwise.

        ``target`` is bound again afterwards."""
        if key != self.key or self._fbo is None or self._fbo.size != target.size:
            return False
        ok = blit(target.glo, self._fbo.glo, target.size, _BOTH)
        target.use()
        if not ok:
            self.key = None
        return ok

    def store(self, key: bytes, target: moderngl.Framebuffer) -> None:
        """Keep ``target``'s colour and depth as ``key``'s view (``target`` is bound again afterwards)."""
        size = target.size
        if self._fbo is None or self._fbo.size != size:
            self._release_fbo()
            self._fbo = self.ctx.framebuffer(
                [colour_texture(self.ctx, size, self.bgra)], self.ctx.depth_renderbuffer(size)
            )
        self.key = key if blit(self._fbo.glo, target.glo, size, _BOTH) else None
        self.stores += 1
        target.use()

    def _release_fbo(self) -> None:
        if self._fbo is not None:
            depth = self._fbo.depth_attachment
            colour = self._fbo.color_attachments[0]
            self._fbo.release()
            if depth is not None:
                depth.release()
            assert isinstance(colour, moderngl.Texture)
            release_texture(colour)
            self._fbo = None
        self.key = None

    def release(self) -> None:
        """Free the GPU objects."""
        self._release_fbo()
