"""Overlay text: strings rendered by ``pygame.font`` into textures, cached per string.

Why pygame.font: it is already a dependency, needs no display (only ``font.init``),
and gives anti-aliased glyphs. Each distinct ``(text, size, colour)`` becomes one RGBA
texture with a 1-pixel dark drop shadow (legible over snow and sky alike); an FPS
counter that changes every frame costs one small texture upload, and an unchanged
line costs nothing. The cache is bounded and forgets the least recently used strings.
"""

from __future__ import annotations

from collections import OrderedDict

import moderngl

__all__ = ["TextCache"]


class TextCache:
    """Textures for overlay strings, least-recently-used eviction past ``capacity``."""

    def __init__(self, ctx: moderngl.Context, capacity: int = 256) -> None:
        import pygame.font

        if not pygame.font.get_init():
            pygame.font.init()
        self._pgfont = pygame.font
        self.ctx = ctx
        self.capacity = capacity
        self._fonts: dict[int, object] = {}
        self._tex: OrderedDict[tuple[str, int, tuple[int, int, int]], moderngl.Texture] = OrderedDict()

    def __len__(self) -> int:
        return len(self._tex)

    def _font(self, size: int):  # type: ignore[no-untyped-def]
        f = self._fonts.get(size)
        if f is None:
            f = self._pgfont.Font(None, size)  # pygame's bundled default font
            self._fonts[size] = f
        return f

    def texture(self, text: str, size: int, color: tuple[float, float, float]) -> moderngl.Texture:
        """The texture of ``text`` (size in pixels, sRGB colour in [0,1]); width/height via ``.size``."""
        rgb = tuple(int(round(255 * min(max(c, 0.0), 1.0))) for c in color)
        key = (text, size, rgb)
        tex = self._tex.get(key)
        if tex is not None:
            self._tex.move_to_end(key)
            return tex
        import pygame

        font = self._font(size)
        fg = font.render(text or " ", True, rgb)
        bg = font.render(text or " ", True, (0, 0, 0))
        surf = pygame.Surface((fg.get_width() + 1, fg.get_height() + 1), pygame.SRCALPHA)
        bg.set_alpha(150)
        surf.blit(bg, (1, 1))
        surf.blit(fg, (0, 0))
        tex = self.ctx.texture(surf.get_size(), 4, pygame.image.tobytes(surf, "RGBA"))
        tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
        self._tex[key] = tex
        while len(self._tex) > self.capacity:
            _, old = self._tex.popitem(last=False)
            old.release()
        return tex

    def release(self) -> None:
        """Free every texture."""
        for t in self._tex.values():
            t.release()
        self._tex.clear()
