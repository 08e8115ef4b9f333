"""Props Alive and Shadow Retargeting on pictures whose answer is known: matte, hole, shadow, deformed surface."""

from __future__ import annotations

import numpy as np
from PIL import Image, ImageDraw, ImageFilter

from games.tasbada.matting import inpaint_hole, matte
from games.tasbada.propmesh import Deform, PropTexture, deform
from games.tasbada.quest import Mark
from games.tasbada.shadow import Shadow, cast, find_shadow, remove_shadows

W, H = 320, 180
FLOOR = 80  # the floor starts at this row
WALL, WOOD, JUG = (210, 205, 190), (150, 105, 70), (40, 70, 200)


def _room(shadow_dx: int = 30) -> np.ndarray:
    """A wall, a wooden floor, a blue jug standing at row 140, its shadow falling to the right."""
    img = Image.new("RGB", (W, H), WALL)
    d = ImageDraw.Draw(img)
    d.rectangle((0, FLOOR, W, H), fill=WOOD)
    shade = Image.new("L", (W, H), 0)
    ImageDraw.Draw(shade).ellipse((140 + shadow_dx - 40, 128, 140 + shadow_dx + 40, 150), fill=110)
    shade = shade.filter(ImageFilter.GaussianBlur(3))
    img = Image.composite(Image.new("RGB", (W, H), (0, 0, 0)), img, shade)
    ImageDraw.Draw(img).ellipse((115, 70, 165, 140), fill=JUG)
    return np.asarray(img).copy()


BOX = Mark("box", [[100 / W, 60 / H], [180 / W, 146 / H]])


def test_grabcut_matte_keeps_the_jug_drops_the_box_and_feathers_the_edge() -> None:
    photo = _room()
    m = matte(photo, BOX)
    alpha = m.full((W, H))
    assert alpha[105, 140] > 0.99 and alpha[72, 140] > 0.5  # body and top of the jug
    assert alpha[62, 102] < 0.01 and alpha[144, 178] < 0.01  # the box's corners: no rectangle
    rim = alpha[105, 105:125]
    assert ((rim > 0.05) & (rim < 0.95)).any()  # a soft edge, not a hard cut
    assert abs(m.base[1] - 140) <= 2 and abs(m.base[0] - 140) <= 3
    assert np.array_equal(matte(photo, BOX).alpha, m.alpha)  # reseeded: the same matte every time


def test_the_hole_is_painted_with_the_room_around_it() -> None:
    photo = _room()
    filled = inpaint_hole(photo, matte(photo, BOX).full((W, H)))
    assert np.abs(filled[110, 140].astype(int) - WOOD).max() < 30  # floor where the jug's body was
    assert np.abs(filled[74, 140].astype(int) - WALL).max() < 40  # wall where its top was


def test_the_shadow_is_found_on_the_side_it_falls_and_lit_out() -> None:
    photo = _room(shadow_dx=30)
    m = matte(photo, BOX)
    s = find_shadow(photo, m, FLOOR)
    assert s.found and s.mask is not None
    assert s.light[0] > 0.05  # it falls to the right: light from the left
    assert 0.2 < s.strength < 0.6
    left = find_shadow(_room(shadow_dx=-30), m, FLOOR)
    assert left.found and left.light[0] < -0.05  # and to the left when it does
    clean = remove_shadows(photo, [s])
    shadowed = (175, 140)
    assert photo[shadowed[1], shadowed[0]].astype(int).sum() < np.sum(WOOD) - 60
    assert abs(int(clean[shadowed[1], shadowed[0]].astype(int).sum()) - int(np.sum(WOOD))) < 45


def test_a_plain_floor_has_no_shadow_and_gets_the_default_light() -> None:
    photo = np.asarray(Image.new("RGB", (W, H), WOOD)).copy()
    photo[:FLOOR] = WALL
    ImageDraw.Draw(img := Image.fromarray(photo)).ellipse((115, 70, 165, 140), fill=JUG)
    s = find_shadow(np.asarray(img).copy(), matte(np.asarray(img).copy(), BOX), FLOOR)
    assert not s.found and s.mask is None


def test_the_recast_shadow_slides_away_and_fades_as_the_prop_rises() -> None:
    alpha = np.zeros((60, 40), np.float32)
    alpha[5:60, 5:35] = 1.0
    s = Shadow((0.5, -0.1), 0.4)
    down, (x0, y0) = cast(alpha, (100, 80), 140.0, s, (W, H))
    up, (x1, y1) = cast(alpha, (100, 50), 140.0, s, (W, H), lift=30.0)

    def centroid(img: np.ndarray, origin: tuple[int, int]) -> float:
        ys, xs = np.mgrid[0 : img.shape[0], 0 : img.shape[1]]
        return float((xs * img).sum() / img.sum()) + origin[0]

    assert centroid(up, (x1, y1)) > centroid(down, (x0, y0)) + 8  # along the light, further away
    assert up.max() < down.max() <= 0.4 + 1e-6  # and fainter


def test_the_surface_squashes_leans_and_opens_a_mouth_with_its_base_on_the_floor() -> None:
    photo = _room()
    tex = PropTexture(photo, matte(photo, BOX))

    def top_and_bottom(d: Deform) -> tuple[float, float, np.ndarray, tuple[int, int]]:
        rgba, (ox, oy) = deform(tex, d)
        rows = np.nonzero((rgba[..., 3] > 128).any(axis=1))[0]
        return oy + rows[0], oy + rows[-1], rgba, (ox, oy)

    t0, b0, rest, _ = top_and_bottom(Deform())
    t1, b1, _, _ = top_and_bottom(Deform(sx=1.15, sy=0.8))
    assert abs(b1 - b0) <= 1 and t1 > t0 + 8  # squashed about its base
    assert np.abs(rest[..., :3][rest[..., 3] > 250].astype(int).mean(axis=0) - JUG).max() < 25  # photo texture
    top, _, leaned, (lx, ly) = top_and_bottom(Deform(lean=0.3))
    r0 = int(top) - ly
    cols_top = np.nonzero(leaned[r0 : r0 + 8, :, 3].max(axis=0) > 128)[0] + lx
    assert cols_top.mean() > 140 + 8  # the top moved right
    _, _, talking, _ = top_and_bottom(Deform(mouth=1.0))
    dark = (talking[..., 3] > 128) & (talking[..., :3].astype(int).sum(axis=2) < 150)
    assert dark.sum() > 10  # a dark mouth opened in the surface
    closed = rest[..., :3].astype(int).sum(axis=2) < 150
    assert not (closed & (rest[..., 3] > 128)).any()  # none while it is closed
