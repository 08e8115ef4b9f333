"""Overlay text: strings rendered by ``pygame.font`` into textures, laid out inside the window.

Why pygame.font: it is already a dependency, needs no display (only ``font.init``),
and gives anti-aliased glyphs. Each distinct ``(text, size, colour)`` becomes one RGBA
texture; an FPS counter that changes every frame costs one small texture upload, and
an unchanged line costs nothing. The cache is bounded and forgets the least recently
used strings.

Readable on anything: every line sits on its own translucent panel, dark behind light
text and light behind dark text, so it keeps its contrast over bright snow, blue sky
or a photo (a 1-pixel shadow alone did not: light text on snow washed out). Panels of
stacked lines abut into one block.

Never off the edge: :func:`layout_text` wraps each line at spaces to the room left
between its start and the window's right margin (a word too long for a line is broken
inside), leaves out what would fall below the bottom margin, and keeps centred lines
(``TextLine.anchor``) inside the window.
"""

from __future__ import annotations

import re
from collections import OrderedDict
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import moderngl

if TYPE_CHECKING:
    import pygame.font

from engine.render.scene import TextLine

__all__ = ["TextCache", "PlacedText", "layout_text", "MARGIN", "PAD_X", "PAD_Y", "panel_rgba"]

MARGIN = 8
"""Pixels kept free at the window's edges."""
PAD_X, PAD_Y = 6, 2
"""The panel's padding around the glyphs, in pixels."""
_DARK_PANEL = (0, 0, 0, 165)
_LIGHT_PANEL = (255, 255, 255, 190)
_TOKENS = re.compile(r"\s+|\S+")


def panel_rgba(rgb: tuple[int, int, int]) -> tuple[int, int, int, int]:
    """The panel behind text of colour ``rgb`` (0-255): dark behind light text, light behind dark."""
    light = 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2] > 110
    return _DARK_PANEL if light else _LIGHT_PANEL


@dataclass(frozen=True)
class PlacedText:
    """One line of a laid-out overlay: the piece of text and its panel's top-left corner in pixels."""

    text: str
    x: float
    y: float
    size: int
    color: tuple[float, float, float]
    alpha: float


class TextCache:
    """Textures for overlay strings, least-recently-used eviction past ``capacity``.

    Measuring and wrapping need only the font, so a cache made with ``ctx=None``
    serves layout (and its tests) without a GL context.
    """

    def __init__(self, ctx: moderngl.Context | None, capacity: int = 256) -> None:
        import pygame.font

        if not pygame.font.get_init():
            pygame.font.init()
        self._pgfont = pygame.font
        self.ctx = ctx
        self.capacity = capacity
        self._fonts: dict[int, pygame.font.Font] = {}
        self._tex: OrderedDict[tuple[str, int, tuple[int, int, int]], moderngl.Texture] = OrderedDict()
        self._wrapped: OrderedDict[tuple[str, int, int], list[str]] = OrderedDict()

    def __len__(self) -> int:
        return len(self._tex)

    def _font(self, size: int) -> pygame.font.Font:
        f = self._fonts.get(size)
        if f is None:
            f = self._pgfont.Font(None, size)  # pygame's bundled default font
            self._fonts[size] = f
        return f

    def measure(self, text: str, size: int) -> tuple[int, int]:
        """Width and height in pixels of the texture (panel included) that ``text`` gets."""
        font = self._font(size)
        return font.size(text or " ")[0] + 2 * PAD_X, font.get_linesize() + 2 * PAD_Y

    def wrap(self, text: str, size: int, max_width: int) -> list[str]:
        """``text`` cut into lines whose textures are at most ``max_width`` wide (at least one character each).

        Breaks at newlines, then at spaces (the spaces at a break are dropped), and
        inside a word only when the word alone is too wide.
        """
        key = (text, size, max_width)
        lines = self._wrapped.get(key)
        if lines is None:
            lines = [piece for para in text.split("\n") for piece in self._wrap_paragraph(para, size, max_width)]
            self._wrapped[key] = lines
            while len(self._wrapped) > 4 * self.capacity:
                self._wrapped.popitem(last=False)
        else:
            self._wrapped.move_to_end(key)
        return lines

    def _fits(self, text: str, size: int, max_width: int) -> bool:
        return self.measure(text, size)[0] <= max_width

    def _wrap_paragraph(self, text: str, size: int, max_width: int) -> list[str]:
        if self._fits(text, size, max_width):
            return [text]
        lines: list[str] = []
        current = ""
        for token in _TOKENS.findall(text):
            if token.isspace():
                current += token
                continue
            if self._fits(current + token, size, max_width):
                current += token
                continue
            if current.strip():
                lines.append(current.rstrip())
            current = token
            while not self._fits(current, size, max_width) and len(current) > 1:
                cut = self._longest_prefix(current, size, max_width)
                lines.append(current[:cut])
                current = current[cut:]
        if current.strip() or not lines:
            lines.append(current.rstrip())
        return lines

    def _longest_prefix(self, word: str, size: int, max_width: int) -> int:
        """How many leading characters of ``word`` fit (at least one), by bisection."""
        lo, hi = 1, len(word)
        while lo < hi:
            mid = (lo + hi + 1) // 2
            if self._fits(word[:mid], size, max_width):
                lo = mid
            else:
                hi = mid - 1
        return lo

    def texture(self, text: str, size: int, color: tuple[float, float, float]) -> moderngl.Texture:
        """The texture of ``text`` on its panel (size in pixels, sRGB colour in [0,1]); width/height via ``.size``."""
        r, g, b = (round(255 * min(max(c, 0.0), 1.0)) for c in color)
        rgb = (r, g, b)
        key = (text, size, rgb)
        tex = self._tex.get(key)
        if tex is not None:
            self._tex.move_to_end(key)
            return tex
        if self.ctx is None:
            raise RuntimeError("this TextCache has no GL context: it can measure and wrap, not make textures")
        import pygame

        glyphs = self._font(size).render(text or " ", True, rgb)
        w, h = self.measure(text, size)
        surf = pygame.Surface((max(w, glyphs.get_width() + 2 * PAD_X), h), pygame.SRCALPHA)
        surf.fill(panel_rgba(rgb))
        surf.blit(glyphs, (PAD_X, PAD_Y))
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
        self._wrapped.clear()


def layout_text(lines: Sequence[TextLine], viewport: tuple[int, int], cache: TextCache) -> list[PlacedText]:
    """Where every piece of every line goes in a ``viewport`` of (width, height) pixels.

    Lines without ``x``/``y`` stack down the left margin; a positioned line wraps
    below its own position. An anchored line is centred on its anchor and shifted
    inside the window if it would cross an edge. Pieces that would still cross the
    bottom edge (more text than the window has room for) are left out.
    """
    width, height = viewport
    cursor = float(MARGIN)
    placed: list[PlacedText] = []
    for line in lines:
        if line.anchor is not None:
            pieces = cache.wrap(line.text, line.size, max(width - 2 * MARGIN, line.size))
            sizes = [cache.measure(p, line.size) for p in pieces]
            total = sum(h for _, h in sizes)
            y = min(max(line.anchor[1] * height - total / 2, MARGIN), max(height - MARGIN - total, MARGIN))
            for piece, (w, h) in zip(pieces, sizes, strict=True):
                x = min(max(line.anchor[0] * width - w / 2, MARGIN), max(width - MARGIN - w, MARGIN))
                if y + h <= height - MARGIN:
                    placed.append(PlacedText(piece, x, y, line.size, line.color, line.alpha))
                y += h
            continue
        x = float(MARGIN) if line.x is None else float(line.x)
        y = cursor if line.y is None else float(line.y)
        for piece in cache.wrap(line.text, line.size, int(max(width - MARGIN - x, line.size))):
            h = cache.measure(piece, line.size)[1]
            if y + h <= height - MARGIN:  # a piece that would cross the bottom edge is left out
                placed.append(PlacedText(piece, x, y, line.size, line.color, line.alpha))
            y += h
        if line.y is None:
            cursor = y
    return placed
