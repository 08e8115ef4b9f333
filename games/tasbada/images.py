"""Image work done once at setup: load and crop the photo, cut out marked objects, fill
the holes they leave, and find the colour of a person's clothes.

All of it is deterministic numpy (no randomness, no threads), so the same photo and
marks always give the same pictures. None of it is simulation state: the quest only
knows marks in normalised image coordinates.

- :func:`fit_photo` crops to 16:9 (the view's aspect) and scales to ``PHOTO_SIZE``.
- :func:`cutout` turns a box or lasso mark into an RGBA sprite (soft-edged alpha).
- :func:`fill_holes` paints over the marked objects with a push–pull fill (a mask-aware
  image pyramid: average down until every hole pixel has a value, then interpolate back
  up), so an animated prop does not leave its still twin behind in the photo.
- :func:`clothes_color` runs k-means (``scipy.cluster.vq.kmeans2`` with a fixed,
  spread initialisation) on the torso region of a selfie and returns the largest cluster.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from PIL import Image, ImageDraw, ImageFilter

from games.tasbada.quest import Mark

__all__ = ["PHOTO_SIZE", "PhotoError", "load_image", "fit_photo", "mark_mask", "cutout", "fill_holes",
           "clothes_color", "TORSO"]

PHOTO_SIZE = (960, 540)
TORSO = (0.3, 0.62, 0.7, 0.98)
"""The torso region of a selfie, ``(u0, v0, u1, v1)``: centred, the lower third of the frame."""

U8 = NDArray[np.uint8]


class PhotoError(ValueError):
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


def mark_mask(mark: Mark, size: tuple[int, int], feather: float = 1.5) -> NDArray[np.float32]:
    """Soft ``[H,W]`` mask in ``[0,1]`` of a mark on an image of ``size`` (w, h)."""
    w, h = size
    m = Image.new("L", size, 0)
    d = ImageDraw.Draw(m)
    pts = mark.points * np.array([w, h])
    if mark.kind == "box":
        (x0, y0), (x1, y1) = pts.min(axis=0), pts.max(axis=0)
        d.rectangle((float(x0), float(y0), float(x1), float(y1)), fill=255)
    else:
        d.polygon([(float(x), float(y)) for x, y in pts], fill=255)
    if feather > 0:
        m = m.filter(ImageFilter.GaussianBlur(feather))
    return np.asarray(m, dtype=np.float32) / 255.0


def cutout(img: U8, mark: Mark) -> tuple[NDArray[np.float32], tuple[int, int, int, int]]:
    """The marked object as a float RGBA sprite ``[h,w,4]`` (0..1) and its pixel box ``(x0, y0, x1, y1)``.

    A box mark keeps its background; its alpha fades towards the edges a little so the
    sprite sits softly in the photo. A lasso keeps exactly its outline.
    """
    h, w = img.shape[:2]
    mask = mark_mask(mark, (w, h))
    u0, v0, u1, v1 = mark.bbox
    x0, y0 = max(int(np.floor(u0 * w)) - 2, 0), max(int(np.floor(v0 * h)) - 2, 0)
    x1, y1 = min(int(np.ceil(u1 * w)) + 2, w), min(int(np.ceil(v1 * h)) + 2, h)
    if x1 - x0 < 2 or y1 - y0 < 2:
        raise PhotoError(f"mark {mark.bbox} covers no pixels")
    rgba = np.zeros((y1 - y0, x1 - x0, 4), dtype=np.float32)
    rgba[..., :3] = img[y0:y1, x0:x1] / 255.0
    rgba[..., 3] = mask[y0:y1, x0:x1]
    if mark.kind == "box":
        rgba[..., 3] *= _foreground(img[y0:y1, x0:x1])
    return rgba, (x0, y0, x1, y1)


def _foreground(patch: U8, threshold: float = 38.0) -> NDArray[np.float32]:
    """Soft alpha of the object inside a box: pixels unlike the box's border colours.

    A box holds background around the object; when the cut-out hops, that background
    would show as a moving rectangle. The border ring samples the background; pixels
    far (in RGB) from every sample are the object. Blobs of at least a tenth of the biggest are kept,
    its holes filled, the edge feathered. Falls back to the whole box if nothing stands out.
    """
    from scipy import ndimage

    p = patch.astype(np.float32)
    ring = np.concatenate([p[0], p[-1], p[:, 0], p[:, -1], p[1], p[-2], p[:, 1], p[:, -2]])
    ring = ring[:: max(len(ring) // 160, 1)]
    dist = np.full(p.shape[:2], np.inf, dtype=np.float32)
    for c in ring:
        dist = np.minimum(dist, np.abs(p - c).sum(axis=2))
    fg = ndimage.binary_opening(dist > threshold, iterations=1)
    labels, n = ndimage.label(fg)
    if n == 0:
        return np.ones(p.shape[:2], dtype=np.float32)
    sizes = ndimage.sum(fg, labels, index=np.arange(1, n + 1))
    big = np.nonzero(sizes >= 0.1 * sizes.max())[0] + 1  # the object and its sizeable parts (a lamp's pole)
    keep = ndimage.binary_fill_holes(np.isin(labels, big))
    keep = ndimage.binary_dilation(keep, iterations=1)
    if keep.mean() < 0.05:
        return np.ones(p.shape[:2], dtype=np.float32)
    return np.clip(ndimage.gaussian_filter(keep.astype(np.float32), 1.0), 0.0, 1.0)


def fill_holes(img: U8, hole: NDArray[np.float32]) -> U8:
    """``img`` with the pixels under ``hole`` (``[H,W]`` in [0,1]) filled from their surroundings."""
    known = (hole < 0.02).astype(np.float64)
    base = img.astype(np.float64)
    levels: list[tuple[NDArray[np.float64], NDArray[np.float64]]] = [(base * known[..., None], known)]
    while levels[-1][1].shape[0] > 2 and levels[-1][1].shape[1] > 2 and levels[-1][1].min() < 1e-6:
        c, k = levels[-1]
        hh, ww = (k.shape[0] // 2) * 2, (k.shape[1] // 2) * 2
        c4 = c[:hh, :ww].reshape(hh // 2, 2, ww // 2, 2, 3).sum(axis=(1, 3))
        k4 = k[:hh, :ww].reshape(hh // 2, 2, ww // 2, 2).sum(axis=(1, 3))
        levels.append((c4, k4))
    # Pull back up: where a level has no data, take the (normalised) coarser estimate.
    c, k = levels[-1]
    est = c / np.maximum(k, 1e-9)[..., None]
    for c, k in reversed(levels[:-1]):
        est_up = _upsample(est, k.shape)
        w = np.clip(k, 0.0, 1.0)[..., None]
        own = c / np.maximum(k, 1e-9)[..., None]
        est = w * own + (1.0 - w) * est_up
    est = 0.35 * est + 0.65 * _row_fill(base, known, est)
    soft = np.clip(hole, 0.0, 1.0)[..., None].astype(np.float64)
    return np.clip(base * (1.0 - soft) + est * soft, 0, 255).astype(np.uint8)


def _row_fill(base: NDArray[np.float64], known: NDArray[np.float64], fallback: NDArray[np.float64]) -> NDArray[np.float64]:
    """Fill each row's gaps by interpolating between the known pixels either side.

    Rooms are full of horizontal structure (the floor line, skirting, shelves), which a
    pyramid fill blurs away; a row-wise fill continues it across the hole.
    """
    out = fallback.copy()
    rows = np.nonzero((known < 0.5).any(axis=1))[0]
    xs = np.arange(base.shape[1])
    for y in rows:
        good = known[y] > 0.5
        if good.sum() < 2:
            continue
        for ch in range(3):
            out[y, :, ch] = np.interp(xs, xs[good], base[y, good, ch])
    return out


def _upsample(a: NDArray[np.float64], shape: tuple[int, ...]) -> NDArray[np.float64]:
    """Bilinear resize of ``[h,w,3]`` to ``shape[:2]`` (per channel, with Pillow's float mode)."""
    out = np.empty((shape[0], shape[1], 3))
    for ch in range(3):
        im = Image.fromarray(a[..., ch].astype(np.float32), "F").resize((shape[1], shape[0]), Image.Resampling.BILINEAR)
        out[..., ch] = np.asarray(im)
    return out


def clothes_color(selfie: U8, k: int = 3, region: tuple[float, float, float, float] = TORSO) -> tuple[float, float, float]:
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
