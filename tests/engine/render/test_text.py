"""Overlay text: wrapped to the window, centred lines kept inside, readable on snow and on sky
(the play overlay's own colours, and dark text as a tool might use).

The wrapping tests need only pygame's font; the pixel tests render on the headless EGL
context (skipped without one) and measure what a reader sees.
"""

import numpy as np
import pytest

from engine.camera import OrbitCamera
from engine.render.headless import egl_available
from engine.render.scene import RenderScene, TextLine
from engine.render.text import MARGIN, PAD_X, PAD_Y, TextCache, layout_text
from puppetphone.overlay import COLORS

W, H = 320, 240
LONG = (
    "mouse: press on the puppet (or a snowball) to grab it, drag to walk or run it, release to let go; "
    "see https://example.invalid/a-very-long-address-without-any-spaces-in-it-at-all"
)
_reason = egl_available()
needs_gl = pytest.mark.skipif(_reason is not None, reason=f"no headless EGL OpenGL 3.3 context: {_reason}")


def font_only():
    """The cache's measuring and wrapping, without a GL context."""
    return TextCache(None)


def test_wrap_keeps_every_piece_within_the_width_and_every_word():
    cache = font_only()
    pieces = cache.wrap(LONG, 18, 200)
    assert len(pieces) > 3
    assert all(cache.measure(p, 18)[0] <= 200 for p in pieces)
    assert "".join(pieces).replace(" ", "") == LONG.replace(" ", "")  # nothing lost, only breaks
    assert cache.wrap("short line", 18, 200) == ["short line"]
    assert cache.wrap("two\nlines", 18, 200) == ["two", "lines"]
    assert cache.wrap("W" * 10, 18, 1) == ["W"] * 10  # always progress, one character at least
    with pytest.raises(RuntimeError):
        cache.texture("no context", 18, (1.0, 1.0, 1.0))


def test_layout_stacks_wraps_and_keeps_centred_lines_inside():
    cache = font_only()
    lines = [
        TextLine("first", size=18),
        TextLine(LONG, size=18),
        TextLine("after", size=18),
        TextLine("notice " * 20, size=40, anchor=(0.5, 0.3)),
        TextLine("corner", size=18, anchor=(1.0, 1.0)),
    ]
    placed = layout_text(lines, (W, H), cache)
    left = [p for p in placed if p.size == 18 and p.text != "corner"]
    assert left[0].text == "first" and left[-1].text == "after"
    assert all(p.x == MARGIN for p in left)
    assert [p.y for p in left] == sorted(p.y for p in left)  # stacked in order, wrapped pieces between
    for p in placed:
        w, h = cache.measure(p.text, p.size)
        assert p.x >= MARGIN and p.x + w <= W - MARGIN, p
        assert p.y >= MARGIN and p.y + h <= H - MARGIN, p
    big = [p for p in placed if p.size == 40]
    assert len(big) > 1 and all(abs(p.x + cache.measure(p.text, 40)[0] / 2 - W / 2) <= 1 for p in big)
    (corner,) = [p for p in placed if p.text == "corner"]
    assert corner.y + cache.measure("corner", 18)[1] <= H - MARGIN
    many = layout_text([TextLine(f"line {i}", size=18) for i in range(40)], (W, H), cache)
    assert 5 < len(many) < 40 and all(p.y + cache.measure(p.text, 18)[1] <= H - MARGIN for p in many)
    assert [p.text for p in many] == [f"line {i}" for i in range(len(many))]  # the first lines, in order


@pytest.fixture(scope="module")
def gl():
    from engine.render import Viewer, make_target

    viewer = Viewer(make_target(True, W, H, samples=0))
    yield viewer
    viewer.close()


def draw(viewer, scene, camera):
    viewer.camera = camera
    viewer.draw(scene)
    return viewer.read_pixels()


@needs_gl
def test_a_long_line_wraps_inside_the_window(gl):
    cam = OrbitCamera()
    plain = draw(gl, RenderScene(), cam).astype(int)
    s = RenderScene()
    s.add_text(LONG, size=18)
    texty = draw(gl, s, cam).astype(int)
    ys, xs = np.nonzero(np.abs(texty - plain).sum(axis=2) > 30)
    assert xs.min() >= MARGIN and xs.max() < W - MARGIN
    assert ys.max() - ys.min() > 3 * 14  # several rows: wrapped, not cut


def relative_luminance(rgb):
    """WCAG 2 relative luminance of sRGB pixels ``[..., 3]`` in 0-255."""
    c = np.asarray(rgb, dtype=np.float64) / 255.0
    lin = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    return lin @ np.array([0.2126, 0.7152, 0.0722])


def glyph_masks(text, size):
    """Glyph cores and their surroundings (two pixels clear of any ink) within the line's panel."""
    import pygame.font

    pygame.font.init()
    font = pygame.font.Font(None, size)
    surf = font.render(text, True, (255, 255, 255))
    ink = np.asarray(pygame.surfarray.pixels_alpha(surf)).T.copy()
    w, h = font_only().measure(text, size)
    core = np.zeros((h, w), bool)
    near = np.zeros((h, w), bool)
    core[PAD_Y : PAD_Y + ink.shape[0], PAD_X : PAD_X + ink.shape[1]] = ink > 250
    any_ink = np.zeros((h, w), bool)
    any_ink[PAD_Y : PAD_Y + ink.shape[0], PAD_X : PAD_X + ink.shape[1]] = ink > 0
    for dy in range(-2, 3):
        for dx in range(-2, 3):
            near |= np.roll(np.roll(any_ink, dy, 0), dx, 1)
    return core, ~near


@needs_gl
@pytest.mark.parametrize("color", [*COLORS.values(), (0.06, 0.08, 0.14)], ids=[*COLORS, "dark"])
@pytest.mark.parametrize("where", ["snow", "sky"])
def test_text_contrast_with_its_surroundings_meets_wcag_aa(gl, color, where):
    text, size = "rolling a snowball  #12  field saved", 20
    if where == "snow":  # looking down: bright sunlit snow fills the frame
        cam, y = OrbitCamera(target=np.zeros(3), pitch=1.2, distance=3.0), 150
    else:  # a level view: sky above the horizon
        cam, y = OrbitCamera(target=np.array([0.0, 1.5, 0.0]), pitch=0.0, distance=5.0), 20
    background = draw(gl, RenderScene(), cam)
    s = RenderScene()
    s.add_text(text, x=20, y=y, size=size, color=color)
    image = draw(gl, s, cam)
    core, around = glyph_masks(text, size)
    box = (slice(y, y + core.shape[0]), slice(20, 20 + core.shape[1]))
    bg = background[box].reshape(-1, 3).astype(float)
    if where == "snow":
        assert relative_luminance(bg).min() > 0.6  # the scene really is bright snow there
    else:
        assert (bg[:, 2] > bg[:, 0] + 30).all()  # and blue sky there
    lum_text = np.median(relative_luminance(image[box][core]))
    lum_around = np.median(relative_luminance(image[box][around]))
    ratio = (max(lum_text, lum_around) + 0.05) / (min(lum_text, lum_around) + 0.05)
    assert ratio >= 4.5, f"contrast {ratio:.2f} of {color} text on {where}"
