"""A prop's real shadow: found in the photo, taken out, and cast again as the prop moves
(Shadow Retargeting, Casas et al. 2018, in the simple form a single photo allows).

**Found.** Around the prop's base, the floor is compared with an estimate of the same
floor without the shadow (the region inpainted from its surroundings, on a quarter-size
image: a shadow is a low-frequency darkening). The connected darker region touching the
base is the shadow; its *ratio* map (photo / unshadowed) says how much light it took.

**Light direction.** A point of the prop at height ``h`` above its base casts its shadow
at ``base + h·L`` on the floor (``L`` in image pixels per pixel of height). The shadow's
centroid sits at the silhouette's mean height ``h̄`` along ``L``, so ``L = (centroid −
base) / h̄``. A person can turn it (the ``light`` option, degrees) when the photo's
shadow is too faint to find.

**Removed** by brightness correction (the photo divided by the smoothed ratio under the
soft shadow mask), so the floor's texture stays. **Re-cast** every frame from the
*deformed* prop: its alpha sheared onto the floor along ``L`` (one affine warp), softened,
and darkened by the measured strength — a hop lifts the silhouette and its shadow slides
away and fades; squash and lean change its shape.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from games.tasbada.matting import Matte

__all__ = ["Shadow", "find_shadow", "remove_shadows", "cast", "DEFAULT_LIGHT", "DEFAULT_STRENGTH"]

DEFAULT_LIGHT = (0.45, -0.12)
"""``L`` when no shadow is found: light from the front left, shadows falling right and back."""
DEFAULT_STRENGTH = 0.35
_DARKER = 0.9
"""A pixel is in the shadow when it has less than this fraction of the unshadowed light."""


@dataclass
class Shadow:
    """One prop's shadow: its light vector, strength, and (if found) its soft mask and ratio in the photo."""

    light: tuple[float, float]
    strength: float
    mask: NDArray[np.float32] | None = None
    """``[H,W]`` 0..1 soft shadow mask on the photo (``None``: no shadow was found)."""
    ratio: NDArray[np.float32] | None = None
    """``[H,W]`` photo / unshadowed light, smoothed (1 outside the shadow)."""
    found: bool = False


def _luma(img: NDArray[np.uint8]) -> NDArray[np.float32]:
    return (img[..., :3].astype(np.float32) @ np.array([0.299, 0.587, 0.114], dtype=np.float32)) + 1.0


def find_shadow(
    photo: NDArray[np.uint8],
    m: Matte,
    floor_row: float,
    others: NDArray[np.float32] | None = None,
    light_deg: float | None = None,
) -> Shadow:
    """The shadow of the prop with matte ``m`` on the floor below image row ``floor_row`` (pixels).

    ``others`` masks the other props (never taken for shadow); ``light_deg`` overrides the
    direction found (0 = shadows fall to the right, 90 = straight back).
    """
    import cv2
    from scipy import ndimage

    h, w = photo.shape[:2]
    alpha = m.full((w, h))
    bx, by = m.base
    height = max(float(m.box[3] - m.box[1]), 8.0)
    radius = 0.75 * height
    ys, xs = np.mgrid[0:h, 0:w]
    floor = ys > floor_row + 2
    region = ((xs - bx) ** 2 + ((ys - by) * 1.6) ** 2 < radius**2) & floor
    blocked = alpha > 0.05
    if others is not None:
        blocked |= others > 0.05
    search = region & ~blocked
    ratio = _ratio(photo, blocked, height, (bx, by), radius)
    dark = ndimage.binary_opening(search & (ratio < _DARKER), iterations=2)  # not the planks' thin seams
    near_base = (xs - bx) ** 2 + (ys - by) ** 2 < (0.15 * height + 6.0) ** 2
    labels, n = ndimage.label(dark)
    touching = np.unique(labels[near_base & dark])
    touching = touching[touching > 0]
    core = np.isin(labels, touching)
    if core.sum() < 0.02 * height * height:
        light = _from_angle(light_deg) if light_deg is not None else DEFAULT_LIGHT
        return Shadow(light, DEFAULT_STRENGTH)
    soft = np.clip((_DARKER + 0.04 - ratio) / 0.1, 0.0, 1.0) * ndimage.binary_dilation(core, iterations=3)
    soft = cv2.GaussianBlur(soft.astype(np.float32), (0, 0), 1.5) * (~blocked)
    strength = float(np.clip(1.0 - np.median(ratio[core]), 0.08, 0.6))
    if light_deg is not None:
        light = _from_angle(light_deg)
    else:
        wgt = soft * (1.0 - np.clip(ratio, 0.0, 1.0))
        cx, cy = float((xs * wgt).sum() / wgt.sum()), float((ys * wgt).sum() / wgt.sum())
        hy = np.clip(by - ys, 0.0, None)
        mean_h = float((hy * alpha).sum() / max(alpha.sum(), 1.0))
        light = ((cx - bx) / max(mean_h, 1.0), (cy - by) / max(mean_h, 1.0))
    r = np.where(soft > 0, np.clip(ratio, 0.4, 1.0), 1.0).astype(np.float32)
    return Shadow((float(light[0]), float(light[1])), strength, soft.astype(np.float32), r, True)


def _ratio(
    photo: NDArray[np.uint8], blocked: NDArray[np.bool_], height: float, around: tuple[float, float], reach: float
) -> NDArray[np.float32]:
    """Light received / light the floor would get without a small dark patch, per pixel (1 far from ``around``).

    The unshadowed light is the *bright envelope* of the luminance: a greyscale closing
    with an ellipse a bit larger than a contact shadow is thick, so a shadow (a dark patch
    smaller than the ellipse) is lifted to its surroundings, while a rug or a floor colour
    (larger than the ellipse) keeps its own level. The props are inpainted first so they
    are not taken for the floor's level. Worked out on the crop within ``reach`` of
    ``around`` at quarter size (a shadow is a low-frequency darkening), then scaled back.
    """
    import cv2

    h, w = photo.shape[:2]
    kx, ky = int(0.9 * height) | 1, int(0.35 * height) | 1
    m = int(reach + kx)
    x0, x1 = max(int(around[0]) - m, 0), min(int(around[0]) + m, w)
    y0, y1 = max(int(around[1]) - m, 0), min(int(around[1]) + m, h)
    crop, hole = photo[y0:y1, x0:x1], blocked[y0:y1, x0:x1].astype(np.uint8)
    k = 4
    sw, sh = max((x1 - x0) // k, 1), max((y1 - y0) // k, 1)
    small = cv2.resize(np.ascontiguousarray(crop), (sw, sh), interpolation=cv2.INTER_AREA)
    small_hole = cv2.dilate(cv2.resize(hole, (sw, sh), interpolation=cv2.INTER_NEAREST), np.ones((3, 3), np.uint8))
    small = cv2.inpaint(small, small_hole * 255, 2, cv2.INPAINT_TELEA)
    lum_small = _luma(np.asarray(small, np.uint8))
    kernel = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (max(kx // k, 1) | 1, max(ky // k, 1) | 1))
    env = cv2.morphologyEx(lum_small, cv2.MORPH_CLOSE, kernel)
    env = cv2.resize(cv2.GaussianBlur(env, (0, 0), 0.75), (x1 - x0, y1 - y0), interpolation=cv2.INTER_LINEAR)
    props = cv2.inpaint(
        np.ascontiguousarray(crop), cv2.dilate(hole, np.ones((3, 3), np.uint8)) * 255, 3, cv2.INPAINT_TELEA
    )
    lum = cv2.GaussianBlur(_luma(np.asarray(props, np.uint8)), (0, 0), 1.5)
    out = np.ones((h, w), dtype=np.float32)
    out[y0:y1, x0:x1] = np.minimum(lum / np.maximum(env, 1.0), 1.5)
    return out


def _from_angle(deg: float, length: float = 0.5) -> tuple[float, float]:
    """``L`` for shadows falling at ``deg`` on the floor (foreshortened: back is shorter in the image)."""
    a = math.radians(deg)
    return (length * math.cos(a), -0.35 * length * math.sin(a))


def remove_shadows(photo: NDArray[np.uint8], shadows: list[Shadow]) -> NDArray[np.uint8]:
    """``photo`` with the found shadows lit again (divided by their ratio under their soft masks)."""
    gain = np.ones(photo.shape[:2], dtype=np.float32)
    for s in shadows:
        if s.found and s.mask is not None and s.ratio is not None:
            gain *= 1.0 + s.mask * (1.0 / s.ratio - 1.0)
    out = photo.astype(np.float32) * gain[..., None]
    return np.clip(out + 0.5, 0, 255).astype(np.uint8)


def cast(
    alpha: NDArray[np.float32],
    origin: tuple[int, int],
    base_y: float,
    s: Shadow,
    size: tuple[int, int],
    lift: float = 0.0,
) -> tuple[NDArray[np.float32], tuple[int, int]]:
    """The shadow a (deformed) prop casts: ``(darkness [h,w] 0..1, top-left (x, y))`` on a picture of ``size``.

    ``alpha`` is the prop's silhouette with its top-left at ``origin`` (pixels), standing on
    row ``base_y``; every pixel at height ``by − y`` lands at ``(x + hL_x, by + hL_y)``.
    ``lift`` (pixels the prop is in the air) softens and fades the shadow.
    """
    import cv2

    lx, ly = s.light
    ly = ly if abs(ly) > 0.04 else math.copysign(0.04, ly if ly != 0 else -1.0)
    ox, oy = origin
    hh, ww = alpha.shape
    # Where the silhouette's corners land, to size the output.
    corners = np.array([[ox, oy], [ox + ww, oy], [ox, oy + hh], [ox + ww, oy + hh]], dtype=np.float64)
    hgt = base_y - corners[:, 1]
    land = np.c_[corners[:, 0] + hgt * lx, base_y + hgt * ly]
    blur = 1.5 + 0.06 * lift
    pad = int(3 * blur) + 2
    x0 = int(max(np.floor(land[:, 0].min()) - pad, 0))
    y0 = int(max(np.floor(land[:, 1].min()) - pad, 0))
    x1 = int(min(np.ceil(land[:, 0].max()) + pad, size[0]))
    y1 = int(min(np.ceil(land[:, 1].max()) + pad, size[1]))
    if x1 - x0 < 2 or y1 - y0 < 2:
        return np.zeros((0, 0), np.float32), (0, 0)
    # Forward map in local coordinates: x' = (x+ox) + (by-(y+oy))·lx - x0, y' = by + (by-(y+oy))·ly - y0.
    mat = np.array(
        [[1.0, -lx, ox + (base_y - oy) * lx - x0], [0.0, -ly, base_y + (base_y - oy) * ly - y0]], dtype=np.float64
    )
    out = cv2.warpAffine(
        alpha.astype(np.float32),
        mat,
        (x1 - x0, y1 - y0),
        flags=cv2.INTER_LINEAR,
        borderMode=cv2.BORDER_CONSTANT,
        borderValue=0,
    )
    out = cv2.GaussianBlur(out, (0, 0), blur)
    fade = s.strength / (1.0 + 0.012 * lift)
    return np.clip(out * fade, 0.0, 1.0).astype(np.float32), (x0, y0)
