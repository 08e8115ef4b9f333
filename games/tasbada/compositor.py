"""The photo side of the view, composed once per drawn frame (never in the simulation).

Three layers, at the photo's resolution (so they line up with the pointer mapping of
:mod:`games.tasbada.view`):

- the **backdrop**: the photo; from stage 2 the photo with the marked props and their
  real shadows taken out (:mod:`~games.tasbada.matting`, :mod:`~games.tasbada.shadow`),
  darkened where each living prop casts its shadow *now*;
- the **props**: each marked thing as a photo-real deformable surface
  (:mod:`~games.tasbada.propmesh`) that hops with squash, stretch and lean; the first is
  the narrator, with eyes that blink and follow the avatar and a mouth that opens in
  its own surface while it talks (Fig. 6.11). Each carries its depth (its base on the
  floor), so the renderer puts it in front of or behind the 3-D things;
- the **interface**: marks, the floor line, buttons, speech bubbles, the selfie and the
  menu, always drawn over the 3-D scene.

Per frame: a copy of the cleaned photo, one remap and one affine warp per prop, and the
interface drawn with Pillow.
"""

from __future__ import annotations

import os
import textwrap
from functools import lru_cache

import numpy as np
from numpy.typing import NDArray
from PIL import Image, ImageDraw, ImageFont

from games.tasbada import marking, narrator, picker
from games.tasbada.matting import inpaint_hole, matte
from games.tasbada.propmesh import Deform, PropTexture, deform
from games.tasbada.quest import MENU, MIXED, PROPS_ALIVE, REAL, STAGES, Mark, Quest
from games.tasbada.shadow import Shadow, cast, find_shadow, remove_shadows

__all__ = ["Sprites", "Layers", "build_sprites", "compose", "composite", "font", "DEPTH_BIAS"]

INK = (32, 28, 40)
PAPER = (255, 252, 244)
ACCENT = (255, 196, 60)


@lru_cache(maxsize=8)
def font(size: int) -> ImageFont.FreeTypeFont | ImageFont.ImageFont:
    """pygame's bundled sans (already a dependency), else Pillow's default font."""
    try:
        import pygame

        return ImageFont.truetype(os.path.join(os.path.dirname(pygame.__file__), "freesansbold.ttf"), size)
    except (ImportError, OSError):
        return ImageFont.load_default()


class Sprites:
    """Stage 2 onwards: the room without its props and their shadows, and each prop's texture,
    shadow and depth point (built once per set of marks)."""

    def __init__(
        self,
        base: NDArray[np.uint8],
        textures: list[PropTexture],
        shadows: list[Shadow],
        depth_at: list[tuple[float, float, float] | None],
    ) -> None:
        self.base = base
        self.textures = textures
        self.shadows = shadows
        self.depth_at = depth_at


PropLayer = tuple[NDArray[np.uint8], tuple[float, float, float, float], tuple[float, float, float] | None]
"""A living prop's picture, its rectangle on the photo (normalised) and the world point it stands at."""


class Layers:
    """One drawn frame of the photo side: the backdrop, the props at their depths, the interface on top."""

    def __init__(self, background: NDArray[np.uint8], props: list[PropLayer], ui: NDArray[np.uint8]) -> None:
        self.background = background
        self.props = props
        """``(rgba, rect, depth_at)`` per prop, ``rect`` normalised on the photo."""
        self.ui = ui


def build_sprites(
    photo: NDArray[np.uint8], marks: list[Mark], ground_v: float = 0.555, light_deg: float | None = None
) -> Sprites:
    """Matte every mark (GrabCut), find its shadow, and clean both out of the photo (once per set of marks)."""
    from games.tasbada.view import floor_point

    h, w = photo.shape[:2]
    mattes = [matte(photo, m) for m in marks]
    alphas = [mt.full((w, h)) for mt in mattes]
    shadows = []
    for i, mt in enumerate(mattes):
        others = np.max([a for j, a in enumerate(alphas) if j != i], axis=0) if len(alphas) > 1 else None
        shadows.append(find_shadow(photo, mt, ground_v * h, others, light_deg))
    textures = [PropTexture(photo, mt, mouth_at=0.36) for mt in mattes]
    clean = remove_shadows(photo, shadows)
    hole = np.max(alphas, axis=0) if alphas else np.zeros((h, w), np.float32)
    base = inpaint_hole(clean, hole)
    depth_at: list[tuple[float, float, float] | None] = []
    for t in textures:
        p = floor_point(t.base[0] / w, t.base[1] / h)
        # A thing standing on the floor is as deep as its base (a little nearer, so it wins its own
        # floor row); one above the horizon (on the wall) stays in the backdrop.
        depth_at.append(None if p is None else (float(p[0]), 0.0, float(p[2]) + DEPTH_BIAS))
    return Sprites(base, textures, shadows, depth_at)


DEPTH_BIAS = 0.12
"""Metres a prop's depth is brought forward from its base (it stands on that floor row)."""


def _button(
    d: ImageDraw.ImageDraw,
    rect: tuple[float, float, float, float],
    label: str,
    size: tuple[int, int],
    hot: bool,
    enabled: bool = True,
) -> None:
    w, h = size
    box = (rect[0] * w, rect[1] * h, rect[2] * w, rect[3] * h)
    fill = (ACCENT if hot else PAPER) if enabled else (200, 200, 200)
    d.rounded_rectangle(box, radius=10, fill=fill + (235,), outline=INK + (255,), width=2)
    f = font(max(int((box[3] - box[1]) * 0.42), 10))
    d.text(((box[0] + box[2]) / 2, (box[1] + box[3]) / 2), label, font=f, fill=INK + (255,), anchor="mm")


def _banner(d: ImageDraw.ImageDraw, text: str, size: tuple[int, int]) -> None:
    w, h = size
    f = font(int(h * 0.034))
    d.rounded_rectangle((w * 0.02, h * 0.885, w * 0.86, h * 0.97), radius=12, fill=(20, 18, 30, 170))
    d.text((w * 0.04, h * 0.9275), text, font=f, fill=(255, 255, 255, 255), anchor="lm")


def _draw_real(img: Image.Image, q: Quest) -> None:
    w, h = img.size
    d = ImageDraw.Draw(img, "RGBA")
    gy = q.ground_v * h
    hot_ground = q.gesture == "ground" or marking.on_ground_handle(q.pointer, q.ground_v)
    line = (ACCENT if hot_ground else (255, 255, 255)) + (255,)
    for x in range(0, w, 28):
        d.line((x, gy, x + 16, gy), fill=line, width=3)
    hx, hr = marking.GROUND_HANDLE_U * w, marking.GROUND_GRAB * h
    d.ellipse((hx - hr, gy - hr, hx + hr, gy + hr), fill=line[:3] + (230,), outline=INK + (255,), width=3)
    for s in (-1.0, 1.0):  # up and down arrows on the knob
        tip, side = gy + s * hr * 0.75, gy + s * hr * 0.25
        d.polygon([(hx, tip), (hx - hr * 0.35, side), (hx + hr * 0.35, side)], fill=INK + (255,))
    d.text(
        (hx + hr + 6, gy - 6),
        "floor line (drag the knob)",
        font=font(int(h * 0.028)),
        fill=(255, 255, 255, 255),
        anchor="lb",
        stroke_width=2,
        stroke_fill=INK + (255,),
    )
    for i, m in enumerate(q.marks):
        pts = m.points * np.array([w, h])
        color = (255, 120, 60, 255) if i == 0 else (90, 200, 255, 255)
        if m.kind == "box":
            (x0, y0), (x1, y1) = pts.min(axis=0), pts.max(axis=0)
            d.rectangle((x0, y0, x1, y1), outline=color, width=4)
            d.rectangle((x0, y0, x1, y1), fill=color[:3] + (40,))
        else:
            d.polygon([tuple(p) for p in pts], outline=color, fill=color[:3] + (40,), width=4)
        u0, v0, _, _ = m.bbox
        tag = "narrator" if i == 0 else f"prop {i}"
        d.text(
            (u0 * w + 4, v0 * h - 4),
            tag,
            font=font(int(h * 0.03)),
            fill=color,
            anchor="lb",
            stroke_width=2,
            stroke_fill=INK + (255,),
        )
    if len(q.path) > 1:
        d.line([(x * w, y * h) for x, y in q.path], fill=(255, 255, 255, 255), width=3)
        (x0, y0), (x1, y1) = q.path[0], q.path[-1]
        d.rectangle((min(x0, x1) * w, min(y0, y1) * h, max(x0, x1) * w, max(y0, y1) * h), outline=(255, 255, 255, 120))
    for b in marking.REAL_BUTTONS:
        _button(d, b.rect, b.label, (w, h), b.contains(q.pointer), enabled=bool(q.marks or q.undo))
    hint = (
        "Drag a box (or draw a lasso) around a thing in your room; the first one will talk."
        if not q.marks
        else f"{len(q.marks)} marked. Mark more, drag the floor line's knob, then press Done."
    )
    _banner(d, hint, (w, h))
    _pointer(d, q, (w, h))


def _pointer(d: ImageDraw.ImageDraw, q: Quest, size: tuple[int, int]) -> None:
    w, h = size
    x, y = q.pointer[0] * w, q.pointer[1] * h
    r = 7 if q.down else 10
    d.ellipse((x - r, y - r, x + r, y + r), outline=(255, 255, 255, 255), width=3)
    d.ellipse((x - 3, y - 3, x + 3, y + 3), fill=INK + (255,))


def _deform(t: PropTexture, m: narrator.PropMotion, img_h: int) -> Deform:
    return Deform(hop=m.hop * img_h, sx=m.sx, sy=m.sy, lean=m.lean, mouth=m.mouth)


def _prop(
    background: NDArray[np.uint8], sp: Sprites, i: int, m: narrator.PropMotion, narrator_face: bool
) -> tuple[NDArray[np.uint8], tuple[int, int]]:
    """Deform prop ``i``, darken the backdrop with the shadow it casts now; its picture and top-left."""
    h, w = background.shape[:2]
    tex = sp.textures[i]
    d = _deform(tex, m, h)
    rgba, origin = deform(tex, d)
    dark, (sx0, sy0) = cast(
        rgba[..., 3].astype(np.float32) / 255.0, origin, tex.base[1], sp.shadows[i], (w, h), lift=d.hop
    )
    if dark.size:
        region = background[sy0 : sy0 + dark.shape[0], sx0 : sx0 + dark.shape[1]]
        region[:] = np.clip(
            region.astype(np.float32) * (1.0 - dark[: region.shape[0], : region.shape[1], None]), 0, 255
        ).astype(np.uint8)
    if narrator_face:
        pic = Image.fromarray(rgba, "RGBA")
        _eyes(ImageDraw.Draw(pic, "RGBA"), tex, d, m, origin)
        rgba = np.asarray(pic)
    return rgba, origin


def _eyes(
    dr: ImageDraw.ImageDraw, tex: PropTexture, d: Deform, m: narrator.PropMotion, origin: tuple[int, int]
) -> None:
    """The narrator's eyes, riding on the deformed surface (they blink and follow the avatar)."""
    bx, by = tex.base
    s = min(tex.width, tex.height)
    er = s * 0.085 * float(np.sqrt(d.sx * d.sy))
    ex = np.array([bx - 0.14 * tex.width, bx + 0.14 * tex.width])
    ey = np.full(2, by - 0.6 * tex.height)
    fx, fy = tex.forward(ex, ey, d)
    eh = er * (1.0 - 0.9 * m.blink)
    for x, y in zip(fx - origin[0], fy - origin[1], strict=True):
        dr.ellipse((x - er, y - eh, x + er, y + eh), fill=(255, 255, 255, 255), outline=INK + (255,), width=2)
        if m.blink < 0.5:
            px, pr = x + m.gaze * er * 0.45, er * 0.48
            dr.ellipse((px - pr, y - pr * 0.9, px + pr, y + pr * 0.9), fill=INK + (255,))
            dr.ellipse((px - pr * 0.05, y - pr * 0.6, px + pr * 0.25, y - pr * 0.1), fill=(255, 255, 255, 220))


def _bubble(d: ImageDraw.ImageDraw, text: str, anchor: tuple[float, float], size: tuple[int, int]) -> None:
    w, h = size
    f = font(int(h * 0.036))
    lines = textwrap.wrap(text, 30)
    lh = int(h * 0.046)
    bw = max(d.textlength(line, font=f) for line in lines) + 36
    bh = lh * len(lines) + 24
    ax, ay = anchor
    bx = float(np.clip(ax - bw * 0.3, 8, w - bw - 8))
    by = float(np.clip(ay - bh - 40, 0.09 * h, h - bh - 8))
    tail = [(ax - 14, by + bh - 2), (ax + 14, by + bh - 2), (ax, min(ay - 6, by + bh + 34))]
    d.rounded_rectangle((bx, by, bx + bw, by + bh), radius=18, fill=PAPER + (250,), outline=INK + (255,), width=3)
    d.polygon(tail, fill=PAPER + (250,), outline=INK + (255,))
    d.line(tail[:2], fill=PAPER + (255,), width=4)
    for i, line in enumerate(lines):
        d.text((bx + 18, by + 12 + i * lh), line, font=f, fill=INK + (255,))


def _selfie_pip(
    img: Image.Image, selfie: Image.Image | None, q: Quest, now: float, color: tuple[float, float, float]
) -> None:
    w, h = img.size
    if selfie is None:
        return
    d = ImageDraw.Draw(img, "RGBA")
    pw = int(w * 0.22)
    ph = int(pw * selfie.height / selfie.width)
    x, y = 16, h - ph - 70
    counting = q.script == "selfie" and q.line < 3
    if counting or q.stage == MIXED and now - q.stage_t < 6.0:
        img.paste(_thumbnail(selfie, (pw, ph)), (x, y))
        d.rectangle((x - 3, y - 3, x + pw + 3, y + ph + 3), outline=PAPER + (255,), width=4)
        if counting:
            n = 3 - q.line
            d.text(
                (x + pw / 2, y + ph / 2),
                str(n),
                font=font(int(ph * 0.5)),
                fill=(255, 255, 255, 230),
                anchor="mm",
                stroke_width=3,
                stroke_fill=INK + (255,),
            )
        else:
            c = tuple(int(255 * v) for v in color)
            d.rectangle((x, y + ph + 10, x + pw, y + ph + 44), fill=c + (255,), outline=PAPER + (255,), width=3)
            d.text(
                (x + pw / 2, y + ph + 27),
                "your colour",
                font=font(20),
                fill=(255, 255, 255, 255),
                anchor="mm",
                stroke_width=2,
                stroke_fill=INK + (255,),
            )
    if q.script == "selfie" and q.line == 3 and now - q.line_t < 0.25:
        d.rectangle((0, 0, w, h), fill=(255, 255, 255, int(220 * (1 - (now - q.line_t) / 0.25))))


def _picker(img: Image.Image, q: Quest) -> None:
    """The pose picker's panel: a stick figure whose elbows, hands, knees and feet can be dragged."""
    w, h = img.size
    d = ImageDraw.Draw(img, "RGBA")
    u0, v0, u1, v1 = picker.PANEL
    d.rounded_rectangle((u0 * w, v0 * h, u1 * w, v1 * h), radius=14, fill=PAPER + (225,), outline=INK + (255,), width=3)
    d.text(
        ((u0 + u1) / 2 * w, v0 * h + 8),
        "Pose your avatar: drag the dots",
        font=font(int(h * 0.026)),
        fill=INK + (255,),
        anchor="mt",
    )

    def px(name: str) -> tuple[float, float]:
        p = picker.to_panel(q.pose[name])
        return (float(p[0] * w), float(p[1] * h))

    for a, b in picker.BONES:
        if a in q.pose and b in q.pose:
            d.line((px(a), px(b)), fill=INK + (255,), width=6)
    if "l_shoulder" in q.pose and "r_shoulder" in q.pose:
        (lx, ly), (rx, ry) = px("l_shoulder"), px("r_shoulder")
        r = abs(lx - rx) * 0.42
        d.ellipse(
            ((lx + rx) / 2 - r, (ly + ry) / 2 - 2.6 * r, (lx + rx) / 2 + r, (ly + ry) / 2 - 0.6 * r),
            outline=INK + (255,),
            width=5,
        )
    for name in picker.HANDLES:
        if name in q.pose:
            x, y = px(name)
            hot = q.gesture == "pose:" + name
            r = 9 if hot else 7
            d.ellipse(
                (x - r, y - r, x + r, y + r),
                fill=(ACCENT if hot else (255, 120, 60)) + (255,),
                outline=INK + (255,),
                width=2,
            )


_THUMBS: dict[tuple[int, int, int], tuple[Image.Image, Image.Image]] = {}


def _thumbnail(picture: Image.Image, size: tuple[int, int]) -> Image.Image:
    """``picture`` at ``size``, resized once per picture (a webcam's selfie is a new picture each frame).

    The cache holds the picture itself too, so its ``id`` cannot be reused by another.
    """
    key = (id(picture), *size)
    if key not in _THUMBS:
        _THUMBS.clear()
        _THUMBS[key] = (picture, picture.resize(size, Image.Resampling.BILINEAR))
    return _THUMBS[key][1]


def _menu(img: Image.Image, q: Quest) -> None:
    w, h = img.size
    d = ImageDraw.Draw(img, "RGBA")
    d.rectangle((0, 0, w, h), fill=(10, 10, 20, 150))
    d.text(
        (w / 2, h * 0.12),
        "Tasbada — where shall we go?",
        font=font(int(h * 0.05)),
        fill=(255, 255, 255, 255),
        anchor="mm",
    )
    reached = [s for s in STAGES if s in q.reached or s in q.saved_reached]
    for b in marking.menu_buttons(reached, q.stage == MENU):
        _button(d, b.rect, b.label, (w, h), b.contains(q.pointer))
    _pointer(d, q, (w, h))


def compose(
    photo: Image.Image,
    sprites: Sprites | None,
    q: Quest,
    now: float,
    selfie: Image.Image | None,
    color: tuple[float, float, float],
    gaze: float,
) -> Layers:
    """This frame's layers: the backdrop ``[H,W,3]``, the living props, the interface ``[H,W,4]``.

    The interface (marks, floor line, buttons, speech bubbles, the selfie, the menu) is
    its own transparent layer, so the view can draw it over the 3-D scene.
    """
    w, h = photo.size
    ui = Image.new("RGBA", (w, h), (0, 0, 0, 0))
    props: list[PropLayer] = []
    if q.stage in (REAL, MENU) or sprites is None:
        background = np.asarray(photo.convert("RGB")).copy()
        if q.stage == REAL and not q.menu_open:
            _draw_real(ui, q)
        elif q.stage not in (REAL, MENU) and q.marks:  # the props are still being cut out
            _banner(ImageDraw.Draw(ui, "RGBA"), "Waking up the things you marked...", (w, h))
    else:
        background = sprites.base.copy()
        t = now - q.alive_t
        talking_text = narrator.script_line(q.script, q.line)
        top: tuple[float, float] | None = None
        for i in range(len(sprites.textures)):
            if i == 0:
                wake = q.stage == PROPS_ALIVE and q.script == "wake" and q.line == 0
                m = narrator.prop_motion(t, 0.0, talking=bool(talking_text), energy=1.6 if wake else 1.0, gaze=gaze)
            else:
                m = narrator.prop_motion(t - 0.4 * i, 0.31 * i, energy=0.6, gaze=gaze)
            rgba, (ox, oy) = _prop(background, sprites, i, m, narrator_face=i == 0)
            if i == 0:
                top = (ox + rgba.shape[1] / 2.0, float(oy + 4))
            at = sprites.depth_at[i]
            if at is None:  # on the wall: part of the backdrop
                _paste(background, rgba, (ox, oy))
            else:
                props.append((rgba, (ox / w, oy / h, (ox + rgba.shape[1]) / w, (oy + rgba.shape[0]) / h), at))
        d = ImageDraw.Draw(ui, "RGBA")
        if top is not None and talking_text:
            _bubble(d, talking_text, top, (w, h))
        if q.pose_picker and q.stage == PROPS_ALIVE:
            _picker(ui, q)
        else:
            _selfie_pip(ui, selfie, q, now, color)
    d = ImageDraw.Draw(ui, "RGBA")
    if q.menu_open or q.stage == MENU:
        _menu(ui, q)
    else:
        _button(d, marking.MENU_BUTTON.rect, marking.MENU_BUTTON.label, (w, h), marking.MENU_BUTTON.contains(q.pointer))
    return Layers(background, props, np.asarray(ui).copy())


def _paste(background: NDArray[np.uint8], rgba: NDArray[np.uint8], origin: tuple[int, int]) -> None:
    """Alpha-blend ``rgba`` into ``background`` at ``origin`` (clipped to the picture)."""
    h, w = background.shape[:2]
    ox, oy = origin
    x0, y0, x1, y1 = max(ox, 0), max(oy, 0), min(ox + rgba.shape[1], w), min(oy + rgba.shape[0], h)
    if x1 <= x0 or y1 <= y0:
        return
    src = rgba[y0 - oy : y1 - oy, x0 - ox : x1 - ox].astype(np.float32)
    a = src[..., 3:] / 255.0
    dst = background[y0:y1, x0:x1]
    dst[:] = np.clip(dst * (1.0 - a) + src[..., :3] * a + 0.5, 0, 255).astype(np.uint8)


def composite(layers: Layers) -> NDArray[np.uint8]:
    """The layers flattened into one ``[H,W,3]`` picture (no 3-D scene): for tests and previews."""
    out = layers.background.copy()
    h, w = out.shape[:2]
    for rgba, rect, _ in layers.props:
        _paste(out, rgba, (int(round(rect[0] * w)), int(round(rect[1] * h))))
    _paste(out, layers.ui, (0, 0))
    return out
