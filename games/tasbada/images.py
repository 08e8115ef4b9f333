"""Image work done once at setup: load and crop the photo, find the colour of a person's clothes.

(Cutting the marked props out and filling their holes is :mod:`games.tasbada.matting`.)

All of it is deterministic numpy (no randomness, no threads), so the same photo and
marks always give the same pictures. None of it is simulation state: the quest only
knows marks in normalised image coordinates.

- :func:`fit_photo` crops to 16:9 (the view's aspect) and scales to ``PHOTO_SIZE``.
- :func:`clothes_color` runs k-means (``scipy.cluster.vq.kmeans2`` with a fixed,
  spread initialisation) on the torso region of a selfie and returns the largest cluster.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image

from engine.arrays import U8
from engine.errors import FormatError

__all__ = ["PHOTO_SIZE", "PhotoError", "load_image", "fit_photo", "clothes_color", "TORSO"]

PHOTO_SIZE = (960, 540)
TORSO = (0.3, 0.62, 0.7, 0.98)
"""The torso region of a selfie, ``(u0, v0, u1, v1)``: centred, the lower third of the frame."""


class PhotoError(FormatError):
    """The picture cannot be used (missing, not an image, too small)."""


def load_image(path: str | Path) -> U8:
    """An RGB ``[H,W,3]`` uint8 picture from a file; :class:`PhotoError` says what is wrong."""
    p = Path(path)
    if not p.is_file():
        raise PhotoError(f"no picture at {p}")
    try:
        with Image.open(p) as im:
            arr = np.asarray(im.convert("RGB"))
    except (OSError, ValueError) as exc:
        raise PhotoError(f"{p} is not a readable picture: {exc}") from exc
    if min(arr.shape[:2]) < 32:
        raise PhotoError(f"{p} is too small ({arr.shape[1]}x{arr.shape[0]}); at least 32 pixels a side")
    return arr


def fit_photo(img: U8, size: tuple[int, int] = PHOTO_SIZE) -> U8:
    """Centre-crop ``img`` to the aspect of ``size`` and resize it there."""
    h, w = img.shape[:2]
    tw, th = size
    if w * th > h * tw:
        cw = int(round(h * tw / th))
        x0 = (w - cw) // 2
        img = img[:, x0 : x0 + cw]
    else:
        ch = int(round(w * th / tw))
        y0 = (h - ch) // 2
        img = img[y0 : y0 + ch]
    out = Image.fromarray(np.ascontiguousarray(img)).resize(size, Image.Resampling.LANCZOS)
    return np.asarray(out).copy()


def clothes_color(
    selfie: U8, k: int = 3, region: tuple[float, float, float, float] = TORSO
) -> tuple[float, float, float]:
    """The representative colour of the clothes: the biggest k-means cluster in the torso region (sRGB 0..1)."""
    from scipy.cluster.vq import kmeans2

    h, w = selfie.shape[:2]
    u0, v0, u1, v1 = region
    patch = selfie[int(v0 * h) : max(int(v1 * h), int(v0 * h) + 1), int(u0 * w) : max(int(u1 * w), int(u0 * w) + 1)]
    px = patch.reshape(-1, 3).astype(np.float64)
    if len(px) > 4096:  # a fixed stride, not a random sample: the same photo gives the same colour
        px = px[:: len(px) // 4096]
    # A spread, deterministic start: pixels at evenly spaced ranks of brightness.
    order = np.argsort(px.sum(axis=1), kind="stable")
    init = px[order[np.linspace(0, len(px) - 1, k).astype(int)]]
    centers, labels = kmeans2(px, init, iter=20, minit="matrix")
    counts = np.bincount(labels, minlength=k)
    c = centers[int(np.argmax(counts))] / 255.0
    return (float(np.clip(c[0], 0, 1)), float(np.clip(c[1], 0, 1)), float(np.clip(c[2], 0, 1)))
