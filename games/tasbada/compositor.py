"""The 2-D layer over the photo, composed once per drawn frame (never in the simulation).

The renderer shows one background picture behind the 3-D world, so everything that
lives *in the photo* is painted into that picture here, with Pillow, at the photo's
resolution (so it lines up with the pointer mapping of :mod:`games.tasbada.view`):

- stage 1: the marks (boxes, lassos, the stroke being drawn), the floor line and the
  Undo/Done buttons;
- from stage 2: the marked objects cut out of the photo (their holes filled once), each
  one a sprite that hops with squash and stretch over a soft shadow that shrinks and
  fades as it rises; the first mark is the narrator, with eyes that blink and follow the
  avatar and a mouth that moves while it talks in a speech bubble (Fig. 6.11);
- the selfie count-down as a picture-in-picture, then the clothes colour swatch;
- the Menu button, and the menu itself when open.

Per frame this is a copy of the filled photo plus a few small sprite resizes and
alpha blends (a few milliseconds for a 960x540 photo).
"""

from __future__ import annotations

import os
import textwrap
from functools import lru_cache

import numpy as np
from numpy.typing import NDArray
from PIL import Image, ImageDraw, ImageFilter, ImageFont

from games.tasbada import marking, narrator
from games.tasbada.images import cutout, fill_holes, mark_mask
from games.tasbada.quest import MENU, MIXED, PROPS_ALIVE, REAL, STAGES, Mark, Quest

__all__ = ["Sprites", "build_sprites", "compose", "font"]

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
    """The cut-outs of the marked objects and the photo with their holes filled."""

    def __init__(self, base: Image.Image, sprites: list[tuple[Image.Image, tuple[int, int, int, int]]],
                 shadow: Image.Image) -> None:
        self.base = base
        self.sprites = sprites
        self.shadow = shadow


def build_sprites(photo: NDArray[np.uint8], marks: list[Mark]) -> Sprites:
    """Cut every mark out of ``photo`` and fill the holes (once per set of marks)."""
    h, w = photo.shape[:2]
    hole = np.zeros((h, w), dtype=np.float32)
    sprites = []
    for m in marks:
        rgba, box = cutout(photo, m)
        sprites.append((Image.fromarray((rgba * 255).astype(np.uint8), "RGBA"), box))
        hole = np.maximum(hole, np.clip(mark_mask(m, (w, h), 2.0) * 1.4, 0, 1))
    base = Image.fromarray(fill_holes(photo, hole)).convert("RGBA")
    sh = Image.new("L", (128, 48), 0)
    ImageDraw.Draw(sh).ellipse((16, 10, 112, 38), fill=170)
    sh = sh.filter(ImageFilter.GaussianBlur(6))
    shadow = Image.new("RGBA", sh.size, (24, 16, 12, 0))
    shadow.putalpha(sh)
    return Sprites(base, sprites, shadow)


def _button(d: ImageDraw.ImageDraw, rect: tuple[float, float, float, float], label: str, size: tuple[int, int],
            hot: bool, enabled: bool = True) -> None:
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
    hot_ground = q.gesture == "ground" or abs(q.pointer[1] - q.ground_v) < marking.GROUND_GRAB
    for x in range(0, w, 28):
        d.line((x, gy, x + 16, gy), fill=(ACCENT if hot_ground else (255, 255, 255)) + (255,), width=3)
    d.text((w * 0.012, gy - 6), "floor line (drag it)", font=font(int(h * 0.028)), fill=(255, 255, 255, 255),
           anchor="lb", stroke_width=2, stroke_fill=INK + (255,))
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
        d.text((u0 * w + 4, v0 * h - 4), tag, font=font(int(h * 0.03)), fill=color, anchor="lb",
               stroke_width=2, stroke_fill=INK + (255,))
    if len(q.path) > 1:
        d.line([(x * w, y * h) for x, y in q.path], fill=(255, 255, 255, 255), width=3)
        (x0, y0), (x1, y1) = q.path[0], q.path[-1]
        d.rectangle((min(x0, x1) * w, min(y0, y1) * h, max(x0, x1) * w, max(y0, y1) * h), outline=(255, 255, 255, 120))
    for b in marking.REAL_BUTTONS:
        _button(d, b.rect, b.label, (w, h), b.contains(q.pointer), enabled=bool(q.marks))
    hint = ("Drag a box (or draw a lasso) around a thing in your room; the first one will talk."
            if not q.marks else f"{len(q.marks)} marked. Mark more, drag the floor line, then press Done.")
    _banner(d, hint, (w, h))
    _pointer(d, q, (w, h))


def _pointer(d: ImageDraw.ImageDraw, q: Quest, size: tuple[int, int]) -> None:
    w, h = size
    x, y = q.pointer[0] * w, q.pointer[1] * h
    r = 7 if q.down else 10
    d.ellipse((x - r, y - r, x + r, y + r), outline=(255, 255, 255, 255), width=3)
    d.ellipse((x - 3, y - 3, x + 3, y + 3), fill=INK + (255,))


def _prop(img: Image.Image, sp: Sprites, i: int, motion: narrator.PropMotion) -> tuple[float, float, float, float]:
    """Paste prop ``i`` (shadow, then the squashed/stretched sprite); returns its drawn box."""
    w, h = img.size
    sprite, (x0, y0, x1, y1) = sp.sprites[i]
    sw, shh = x1 - x0, y1 - y0
    nw, nh = max(int(round(sw * motion.sx)), 2), max(int(round(shh * motion.sy)), 2)
    lift = motion.hop * h
    cx, base_y = (x0 + x1) / 2.0, float(y1)
    # Shadow: wide as the base, smaller and fainter as the prop rises.
    k = max(0.35, 1.0 - 6.0 * motion.hop)
    shw, shh2 = max(int(sw * 0.95 * motion.sx * k), 4), max(int(sw * 0.22 * k), 3)
    shadow = sp.shadow.resize((shw, shh2), Image.Resampling.BILINEAR)
    if k < 1.0:
        shadow.putalpha(shadow.getchannel("A").point(lambda a: int(a * k)))
    img.alpha_composite(shadow, (int(cx - shw / 2), int(base_y - shh2 * 0.6)))
    scaled = sprite.resize((nw, nh), Image.Resampling.BILINEAR)
    left, top = int(round(cx - nw / 2)), int(round(base_y - lift - nh))
    if left >= w or top >= h or left + nw <= 0 or top + nh <= 0:
        return (left, top, left + nw, top + nh)
    crop = scaled.crop((max(-left, 0), max(-top, 0), min(nw, w - left), min(nh, h - top)))
    img.alpha_composite(crop, (max(left, 0), max(top, 0)))
    return (left, top, left + nw, top + nh)


def _face(d: ImageDraw.ImageDraw, box: tuple[float, float, float, float], m: narrator.PropMotion) -> None:
    x0, y0, x1, y1 = box
    bw, bh = x1 - x0, y1 - y0
    s = min(bw, bh)
    er = s * 0.09
    eh = er * (1.0 - 0.9 * m.blink)
    for ex in (x0 + bw * 0.36, x0 + bw * 0.64):
        ey = y0 + bh * 0.42
        d.ellipse((ex - er, ey - eh, ex + er, ey + eh), fill=(255, 255, 255, 255), outline=INK + (255,), width=2)
        if m.blink < 0.5:
            px = ex + m.gaze * er * 0.45
            pr = er * 0.48
            d.ellipse((px - pr, ey - pr * 0.9, px + pr, ey + pr * 0.9), fill=INK + (255,))
            d.ellipse((px - pr * 0.35 + pr * 0.3, ey - pr * 0.6, px + pr * 0.25, ey - pr * 0.1), fill=(255, 255, 255, 220))
    mx, my = x0 + bw * 0.5, y0 + bh * 0.62
    mw = s * 0.16
    if m.mouth > 0.05:
        mh = s * 0.12 * m.mouth
        d.ellipse((mx - mw, my - mh * 0.4, mx + mw, my + mh), fill=(90, 20, 30, 255), outline=INK + (255,), width=2)
    else:
        d.arc((mx - mw, my - mw * 0.6, mx + mw, my + mw * 0.6), 20, 160, fill=INK + (255,), width=3)


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


def _selfie_pip(img: Image.Image, selfie: Image.Image | None, q: Quest, now: float, color: tuple[float, float, float]) -> None:
    w, h = img.size
    if selfie is None:
        return
    d = ImageDraw.Draw(img, "RGBA")
    pw = int(w * 0.22)
    ph = int(pw * selfie.height / selfie.width)
    x, y = 16, h - ph - 70
    counting = q.script == "selfie" and q.line < 3
    if counting or q.stage == MIXED and now - q.stage_t < 6.0:
        img.paste(selfie.resize((pw, ph), Image.Resampling.BILINEAR), (x, y))
        d.rectangle((x - 3, y - 3, x + pw + 3, y + ph + 3), outline=PAPER + (255,), width=4)
        if counting:
            n = 3 - q.line
            d.text((x + pw / 2, y + ph / 2), str(n), font=font(int(ph * 0.5)), fill=(255, 255, 255, 230), anchor="mm",
                   stroke_width=3, stroke_fill=INK + (255,))
        else:
            c = tuple(int(255 * v) for v in color)
            d.rectangle((x, y + ph + 10, x + pw, y + ph + 44), fill=c + (255,), outline=PAPER + (255,), width=3)
            d.text((x + pw / 2, y + ph + 27), "your colour", font=font(20), fill=(255, 255, 255, 255), anchor="mm",
                   stroke_width=2, stroke_fill=INK + (255,))
    if q.script == "selfie" and q.line == 3 and now - q.line_t < 0.25:
        d.rectangle((0, 0, w, h), fill=(255, 255, 255, int(220 * (1 - (now - q.line_t) / 0.25))))


def _menu(img: Image.Image, q: Quest) -> None:
    w, h = img.size
    d = ImageDraw.Draw(img, "RGBA")
    d.rectangle((0, 0, w, h), fill=(10, 10, 20, 150))
    d.text((w / 2, h * 0.12), "Tasbada — where shall we go?", font=font(int(h * 0.05)), fill=(255, 255, 255, 255),
           anchor="mm")
    reached = [s for s in STAGES if s in q.reached or s in q.saved_reached]
    for b in marking.menu_buttons(reached, q.stage == MENU):
        _button(d, b.rect, b.label, (w, h), b.contains(q.pointer))
    _pointer(d, q, (w, h))


def compose(photo: Image.Image, sprites: Sprites | None, q: Quest, now: float, selfie: Image.Image | None,
            color: tuple[float, float, float], gaze: float) -> NDArray[np.uint8]:
    """This frame's background picture ``[H,W,3]`` uint8 (a new array every call).

    Sprites are blended on an RGBA canvas; the drawing after that happens on RGB,
    where Pillow's ``"RGBA"`` draw mode blends translucent fills instead of replacing.
    """
    if q.stage in (REAL, MENU) or sprites is None:
        img = photo.convert("RGB")
        if q.stage == REAL and not q.menu_open:
            _draw_real(img, q)
    else:
        canvas = sprites.base.copy()
        t = now - q.alive_t
        talking_text = narrator.script_line(q.script, q.line)
        boxes, motions = [], []
        for i in range(len(sprites.sprites)):
            if i == 0:
                wake = q.stage == PROPS_ALIVE and q.script == "wake" and q.line == 0
                m = narrator.prop_motion(t, 0.0, talking=bool(talking_text), energy=1.6 if wake else 1.0, gaze=gaze)
            else:
                m = narrator.prop_motion(t - 0.4 * i, 0.31 * i, energy=0.6, gaze=gaze)
            boxes.append(_prop(canvas, sprites, i, m))
            motions.append(m)
        img = canvas.convert("RGB")
        d = ImageDraw.Draw(img, "RGBA")
        if boxes:
            _face(d, boxes[0], motions[0])
            if talking_text:
                _bubble(d, talking_text, ((boxes[0][0] + boxes[0][2]) / 2, boxes[0][1]), img.size)
        _selfie_pip(img, selfie, q, now, color)
    d = ImageDraw.Draw(img, "RGBA")
    if q.menu_open or q.stage == MENU:
        _menu(img, q)
    else:
        _button(d, marking.MENU_BUTTON.rect, marking.MENU_BUTTON.label, img.size,
                marking.MENU_BUTTON.contains(q.pointer))
    return np.asarray(img).copy()
