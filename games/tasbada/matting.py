"""Cutting a real prop out of the photo (Props Alive, Casas et al. 2017): matte and hole.

A person marks a thing with a box or a lasso; :func:`matte` separates it from the
room with OpenCV's GrabCut, seeded by that mark (outside = certain background, inside =
probable foreground), and turns the hard segmentation into a *feathered* alpha: a
narrow soft ramp across the edge, so the animated prop shows no cut-out rectangle and
no jagged rim. :func:`inpaint_hole` then paints the room over the place the prop
stood (OpenCV's Telea inpainting), so the prop can move without leaving its still twin.

Both run once per set of marks, at display time only: nothing the simulation hashes
depends on them. GrabCut's Gaussian-mixture initialisation draws from OpenCV's global
random generator, so :func:`matte` reseeds it before every call — the same photo and
mark give the same matte whatever ran before.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from games.tasbada.quest import Mark

__all__ = ["Matte", "matte", "inpaint_hole", "FEATHER"]

FEATHER = 1.6
"""Half-width, in pixels, of the soft ramp across the prop's edge."""
_ITERATIONS = 5
_MARGIN = 6
"""Pixels of room kept around the mark in the working crop (GrabCut needs some background)."""


class Matte:
    """A prop's alpha ``[h,w]`` (0..1) in the crop ``box = (x0, y0, x1, y1)`` of the photo."""

    __slots__ = ("alpha", "box")

    def __init__(self, alpha: NDArray[np.float32], box: tuple[int, int, int, int]) -> None:
        self.alpha = alpha
        self.box = box

    def full(self, size: tuple[int, int]) -> NDArray[np.float32]:
        """The alpha placed on a whole picture of ``size`` (w, h)."""
        w, h = size
        out = np.zeros((h, w), dtype=np.float32)
        x0, y0, x1, y1 = self.box
        out[y0:y1, x0:x1] = self.alpha
        return out

    @property
    def base(self) -> tuple[float, float]:
        """Where the prop touches the floor: ``(x, y)`` pixels, the middle of its lowest solid row."""
        x0, y0, _, _ = self.box
        rows = np.nonzero((self.alpha > 0.5).any(axis=1))[0]
        if len(rows) == 0:
            return (x0 + self.alpha.shape[1] / 2.0, float(self.box[3]))
        y = int(rows[-1])
        band = self.alpha[max(y - 3, 0) : y + 1] > 0.5
        xs = np.nonzero(band.any(axis=0))[0]
        return (x0 + float(xs.mean()), y0 + float(y) + 1.0)


def _seed(shape: tuple[int, int], mark: Mark, crop: tuple[int, int, int, int]) -> NDArray[np.uint8]:
    """The GrabCut seed mask of the crop: outside the mark background, inside probably the prop."""
    import cv2

    x0, y0, x1, y1 = crop
    h, w = shape
    mask = np.full((y1 - y0, x1 - x0), cv2.GC_BGD, dtype=np.uint8)
    pts = mark.points * np.array([w, h]) - np.array([x0, y0])
    if mark.kind == "box":
        (a0, b0), (a1, b1) = np.floor(pts.min(axis=0)).astype(int), np.ceil(pts.max(axis=0)).astype(int)
        mask[max(b0, 0) : b1, max(a0, 0) : a1] = cv2.GC_PR_FGD
    else:
        cv2.fillPoly(mask, [np.round(pts).astype(np.int32)], int(cv2.GC_PR_FGD))
    return mask


def matte(photo: NDArray[np.uint8], mark: Mark) -> Matte:
    """The feathered alpha of the thing inside ``mark`` (GrabCut seeded by the mark)."""
    import cv2

    h, w = photo.shape[:2]
    u0, v0, u1, v1 = mark.bbox
    crop = (
        max(int(np.floor(u0 * w)) - _MARGIN, 0),
        max(int(np.floor(v0 * h)) - _MARGIN, 0),
        min(int(np.ceil(u1 * w)) + _MARGIN, w),
        min(int(np.ceil(v1 * h)) + _MARGIN, h),
    )
    x0, y0, x1, y1 = crop
    if x1 - x0 < 8 or y1 - y0 < 8:
        return Matte(np.ones((max(y1 - y0, 1), max(x1 - x0, 1)), dtype=np.float32), crop)
    mask = _seed((h, w), mark, crop)
    patch = np.ascontiguousarray(photo[y0:y1, x0:x1, ::-1])  # OpenCV works in BGR
    bgd, fgd = np.zeros((1, 65), np.float64), np.zeros((1, 65), np.float64)
    cv2.setRNGSeed(12345)
    if (mask == cv2.GC_PR_FGD).any() and (mask == cv2.GC_BGD).any():
        cv2.grabCut(
            patch,
            mask,
            None,
            bgd,
            fgd,
            _ITERATIONS,  # type: ignore[call-overload]  # rect unused with a mask
            cv2.GC_INIT_WITH_MASK,
        )
    hard = np.isin(mask, (cv2.GC_FGD, cv2.GC_PR_FGD)).astype(np.uint8)
    # Slivers of the room along the prop (a strip of skirting board) are thinner than any part of it.
    hard = np.asarray(
        cv2.morphologyEx(hard, cv2.MORPH_OPEN, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (5, 5))), np.uint8
    )
    hard = _largest_parts(hard)
    if hard.mean() < 0.02:  # nothing stood out: keep the marked region itself
        hard = (_seed((h, w), mark, crop) == cv2.GC_PR_FGD).astype(np.uint8)
    return Matte(_feather(hard), crop)


def _largest_parts(hard: NDArray[np.uint8]) -> NDArray[np.uint8]:
    """Keep the blobs of at least a tenth of the biggest (the prop and its sizeable parts), small holes filled.

    A small hole is a speck GrabCut missed (a highlight); a large one is the room seen
    through the prop (between a plant's leaves) and stays open.
    """
    from scipy import ndimage

    labels, n = ndimage.label(hard)
    if n == 0:
        return hard
    sizes = ndimage.sum(hard, labels, index=np.arange(1, n + 1))
    keep = np.isin(labels, np.nonzero(sizes >= 0.1 * sizes.max())[0] + 1)
    holes, m = ndimage.label(ndimage.binary_fill_holes(keep) & ~keep)
    if m:
        area = ndimage.sum(np.ones_like(keep), holes, index=np.arange(1, m + 1))
        keep |= np.isin(holes, np.nonzero(area < 0.01 * keep.sum())[0] + 1)
    return keep.astype(np.uint8)


def _feather(hard: NDArray[np.uint8]) -> NDArray[np.float32]:
    """A soft edge from a hard mask: signed distance to the edge through a linear ramp of ±:data:`FEATHER`."""
    import cv2

    inside = cv2.distanceTransform(hard, cv2.DIST_L2, 3)
    outside = cv2.distanceTransform(1 - hard, cv2.DIST_L2, 3)
    signed = np.where(hard > 0, inside - 0.5, 0.5 - outside)
    return np.clip(0.5 + signed / (2.0 * FEATHER), 0.0, 1.0).astype(np.float32)


def inpaint_hole(photo: NDArray[np.uint8], hole: NDArray[np.float32], grow: int = 4) -> NDArray[np.uint8]:
    """``photo`` with the region under ``hole`` (``[H,W]`` 0..1) painted from its surroundings (Telea).

    The hole is grown by ``grow`` pixels so the prop's soft rim and its colour bleed go too.
    """
    import cv2

    mask = (hole > 0.02).astype(np.uint8)
    if not mask.any():
        return photo.copy()
    mask = np.asarray(cv2.dilate(mask, np.ones((2 * grow + 1, 2 * grow + 1), np.uint8)), np.uint8)
    out = cv2.inpaint(np.ascontiguousarray(photo[..., ::-1]), mask * 255, 5, cv2.INPAINT_TELEA)
    return np.ascontiguousarray(out[..., ::-1])
