"""The photo-real prop as a deformable textured surface (Props Alive): squash, stretch, lean, a mouth.

The prop's texture is the photo itself under its matte. Its surface is deformed by a
smooth map from the rest shape to the animated one, in coordinates relative to the
base point ``(X right, Y up)``:

1. **mouth** (the narrator): above the mouth line ``Y_m`` the surface lifts by
   ``gap(X)·fall(Y−Y_m)`` — an upper lip that opens over a dark mouth inside, fading out
   towards the top so the rest of the prop keeps its shape;
2. **squash/stretch** about the base: ``X·sx``, ``Y·sy``;
3. **lean**: a shear growing with height, ``X + lean·Y``;
4. **hop**: the whole surface lifted by ``hop`` pixels.

Rendering inverts this map at every output pixel (one vertex per pixel of a dense
mesh, resampled bilinearly with ``cv2.remap``): steps 4–2 invert in closed form, the
mouth by a short fixed-point iteration (it is a contraction while ``gap < fall``'s
height). The texture never scales by a sprite resize, so it stays sharp and its
feathered edge stays soft.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from games.tasbada.matting import Matte

__all__ = ["Deform", "PropTexture", "deform"]

MOUTH_COLOR = (70, 18, 24)


@dataclass(frozen=True)
class Deform:
    """One frame's deformation, in pixels and ratios (see the module doc)."""

    hop: float = 0.0
    sx: float = 1.0
    sy: float = 1.0
    lean: float = 0.0
    mouth: float = 0.0
    """Mouth opening 0..1 (0 closed: no mouth drawn)."""


class PropTexture:
    """A prop's RGBA texture cut from the photo by its matte, with its base and mouth line."""

    def __init__(self, photo: NDArray[np.uint8], m: Matte, mouth_at: float = 0.36) -> None:
        x0, y0, x1, y1 = m.box
        self.rgba = np.dstack([photo[y0:y1, x0:x1], np.round(m.alpha * 255).astype(np.uint8)])
        self.box = m.box
        self.base = m.base
        solid = np.nonzero((m.alpha > 0.5).any(axis=1))[0]
        top = float(y0 + solid[0]) if len(solid) else float(y0)
        self.height = max(self.base[1] - top, 4.0)
        cols = np.nonzero((m.alpha > 0.5).any(axis=0))[0]
        self.width = float(cols[-1] - cols[0] + 1) if len(cols) else float(x1 - x0)
        self.mouth_y = mouth_at * self.height
        """The mouth line, pixels above the base."""
        self.mouth_w = 0.16 * min(self.width, self.height * 1.2)
        self.mouth_x = float(self.base[0])

    def forward(
        self, x: NDArray[np.float64], y: NDArray[np.float64], d: Deform
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Photo pixel positions on the rest prop → where they are drawn under ``d``."""
        bx, by = self.base
        X, Y = x - bx, by - y
        Y = Y + self._lift(X, Y, d)
        X, Y = X * d.sx, Y * d.sy
        X = X + d.lean * Y
        Y = Y + d.hop
        return bx + X, by - Y

    def _gap(self, X: NDArray[np.float64], d: Deform) -> NDArray[np.float64]:
        t = (X - (self.mouth_x - self.base[0])) / self.mouth_w
        return d.mouth * 0.09 * self.height * np.clip(1.0 - t * t, 0.0, None) ** 0.7

    def _fall_height(self) -> float:
        return 0.3 * self.height

    def _lift(self, X: NDArray[np.float64], Y: NDArray[np.float64], d: Deform) -> NDArray[np.float64]:
        if d.mouth <= 0:
            return np.zeros_like(Y)
        above = np.clip((Y - self.mouth_y) / self._fall_height(), 0.0, 1.0)
        return np.where(self.mouth_y <= Y, self._gap(X, d) * (1.0 - above), 0.0)


def deform(tex: PropTexture, d: Deform) -> tuple[NDArray[np.uint8], tuple[int, int]]:
    """The prop drawn under ``d``: an RGBA image and its top-left in photo pixels."""
    import cv2

    x0, y0, x1, y1 = tex.box
    cx = np.array([x0, x1, x0, x1], dtype=np.float64)
    cy = np.array([y0, y0, y1, y1], dtype=np.float64)
    fx, fy = tex.forward(cx, cy, d)
    pad = 3 + int(np.ceil(0.1 * tex.height * d.mouth))
    ox, oy = int(np.floor(fx.min())) - pad, int(np.floor(fy.min())) - pad
    ow, oh = int(np.ceil(fx.max())) + pad - ox, int(np.ceil(fy.max())) + pad - oy
    bx, by = tex.base
    xs, ys = np.meshgrid(np.arange(ow, dtype=np.float64) + ox, np.arange(oh, dtype=np.float64) + oy)
    # Invert hop, lean, scale (closed form).
    Yb = (by - ys) - d.hop
    Xb = (xs - bx) - d.lean * Yb
    X, Ya = Xb / d.sx, Yb / d.sy
    Y = Ya.copy()
    inside_mouth = np.zeros(Y.shape, dtype=bool)
    gap = None
    if d.mouth > 0:
        gap = tex._gap(X, d)  # depends on X only: once per frame
        inside_mouth = (Ya >= tex.mouth_y) & (Ya < tex.mouth_y + gap) & (gap > 0.5)
        up = Ya >= tex.mouth_y + gap
        Yu = Ya - gap
        fall = tex._fall_height()
        for _ in range(6):  # Y = Ya − gap·(1 − fall(Y − Y_m)): a contraction above the mouth line
            Yu = Ya - gap * (1.0 - np.clip((Yu - tex.mouth_y) / fall, 0.0, 1.0))
        Y = np.where(up, Yu, Y)
    mapx = (bx + X - x0).astype(np.float32)
    mapy = (by - Y - y0).astype(np.float32)
    out = np.asarray(
        cv2.remap(tex.rgba, mapx, mapy, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT, borderValue=0), np.uint8
    )
    if gap is not None and inside_mouth.any():
        lip_y = np.asarray(by - tex.mouth_y - y0, dtype=np.float32)
        a = cv2.remap(
            tex.rgba[..., 3],
            mapx,
            np.full_like(mapy, lip_y),
            cv2.INTER_LINEAR,
            borderMode=cv2.BORDER_CONSTANT,
            borderValue=0,
        )
        shade = np.clip((Ya - tex.mouth_y) / np.maximum(gap, 1.0), 0.0, 1.0)
        inner = np.array(MOUTH_COLOR, dtype=np.float32)[None, None, :] * (0.6 + 0.4 * shade[..., None])
        out[inside_mouth, :3] = inner[inside_mouth].astype(np.uint8)
        out[inside_mouth, 3] = a[inside_mouth]
    return out, (ox, oy)
