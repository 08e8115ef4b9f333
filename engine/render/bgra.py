"""Colour textures stored as BGRA: the layout Mesa llvmpipe's linear rasteriser copies fast.

At quality ``low`` and ``medium`` the 3-D scene is drawn into a smaller buffer and
stretched over the frame by one full-screen textured pass. On llvmpipe that pass cost
more than a clear of the frame (4.5-5.6 ms at 1280x720 against ~1.1-1.8 ms), because each
pixel went through the general per-pixel shader path. llvmpipe has a second path for
exactly this kind of pass (one texture fetch, no depth buffer bound, no blending): the
"linear" rasteriser, which copies rows of texels with SIMD code. It is taken only when
the source texture and the destination are both stored B8G8R8A8; measured in isolation
it brought the stretch from 4.5 to 2.2-3.3 ms. (A scaled ``glBlitFramebuffer`` cost 6-8 ms.)

moderngl allocates ``GL_RGBA8`` from ``GL_RGBA`` data, which Mesa stores R8G8B8A8. Mesa
picks the storage that matches the client data only for an *unsized* internal format:
``GL_RGBA`` from ``GL_BGRA`` data is stored B8G8R8A8 (``GL_RGBA8`` from the same data was
not: no gain, measured). So :func:`colour_texture` allocates the texture itself with that
one call through the system GL library (:mod:`engine.render.rawgl`) and wraps it with
``ctx.external_texture``. To GL and to moderngl it is an ordinary 8-bit RGBA texture:
drawing, sampling and reading pixels back give the same values as before.
Where the library cannot be loaded, or on a GPU (which has no use for it), it is a plain
moderngl texture.
"""

from __future__ import annotations

import ctypes

import moderngl

from engine.render.rawgl import clear_errors, gl

__all__ = ["colour_texture", "release_texture"]

_TEXTURE_2D, _RGBA, _BGRA, _UNSIGNED_BYTE = 0x0DE1, 0x1908, 0x80E1, 0x1401
_TEXTURE_BINDING_2D, _NO_ERROR = 0x8069, 0
_OWNED = "bgra-owned"
"""``Texture.extra`` of the textures made here: their GL name is ours to delete."""


def _bgra_name(gl: ctypes.CDLL, size: tuple[int, int]) -> int | None:
    """A new texture name holding ``size`` of BGRA-stored 8-bit RGBA storage (``None`` if GL refused)."""
    clear_errors(gl)
    bound, name = ctypes.c_int(0), ctypes.c_uint(0)
    gl.glGetIntegerv(_TEXTURE_BINDING_2D, ctypes.byref(bound))
    gl.glGenTextures(1, ctypes.byref(name))
    gl.glBindTexture(_TEXTURE_2D, name.value)
    gl.glTexImage2D(_TEXTURE_2D, 0, _RGBA, size[0], size[1], 0, _BGRA, _UNSIGNED_BYTE, None)
    ok = gl.glGetError() == _NO_ERROR
    gl.glBindTexture(_TEXTURE_2D, bound.value)  # leave the unit as moderngl left it
    if not ok or name.value == 0:
        gl.glDeleteTextures(1, ctypes.byref(name))
        return None
    return int(name.value)


def colour_texture(ctx: moderngl.Context, size: tuple[int, int], bgra: bool) -> moderngl.Texture:
    """An RGBA8 colour texture of ``size``, stored as BGRA when ``bgra`` (callers ask for it on a
    software rasteriser) and the GL library is reachable; release it with :func:`release_texture`."""
    lib = gl() if bgra else None
    name = _bgra_name(lib, size) if lib is not None else None
    if name is None:
        return ctx.texture(size, 4)
    tex = ctx.external_texture(name, size, 4, 0, "f1")
    tex.extra = _OWNED
    tex.filter = (moderngl.LINEAR, moderngl.LINEAR)  # complete without mipmaps, as moderngl's own are
    return tex


def release_texture(tex: moderngl.Texture) -> None:
    """Release a texture from :func:`colour_texture` (an external one's GL name is deleted too:
    moderngl leaves external names alone)."""
    name = tex.glo
    tex.release()
    lib = gl()
    if tex.extra == _OWNED and lib is not None and name > 0:
        lib.glDeleteTextures(1, ctypes.byref(ctypes.c_uint(name)))
        tex.extra = None
