"""Keep authored pelvis heights within the legs' reach, smoothly.

A keyed pelvis curve is what the animator wants; the legs are what the ankles allow. Where
a leg would have to stretch past ``max_reach`` of its length, the pelvis is lowered just
enough, with the lowering dilated and then box-blurred so it eases in and out instead of
making a kink. Dilating by twice the blur radius guarantees the smoothed lowering is never
less than what each frame needs, so no ankle target is left out of reach.
"""

from __future__ import annotations

import numpy as np
from scipy.ndimage import maximum_filter1d, uniform_filter1d

from engine import quat
from engine.arrays import F64 as F
from engine.skeleton import Skeleton

__all__ = ["lower_to_reach", "smooth_envelope"]


def lower_to_reach(
    skeleton: Skeleton,
    pelvis_pos: F,
    pelvis_rot: F,
    ankles: F,
    max_reach: float,
    radius: int,
    loop: bool,
) -> F:
    """Pelvis heights ``[N]`` no higher than keyed and low enough for both legs.

    Args:
        skeleton: the puppet (thigh offsets and leg lengths are read from it).
        pelvis_pos: ``[N,3]`` keyed pelvis positions.
        pelvis_rot: ``[N,4]`` pelvis world rotations.
        ankles: ``[N,2,3]`` ankle targets (left, right).
        max_reach: largest allowed hip-to-ankle distance as a fraction of thigh + shin.
        radius: blur radius in frames of the lowering.
        loop: whether the track wraps (cycles) or is clamped at its ends.
    """
    y = pelvis_pos[:, 1].copy()
    allowed = np.full(len(y), np.inf)
    for s, side in enumerate(("l", "r")):
        up = skeleton.index(f"{side}_upper_leg")
        length = sum(
            float(np.linalg.norm(skeleton.offsets[skeleton.index(f"{side}_{b}")])) for b in ("lower_leg", "foot")
        )
        hip_off = quat.rotate(pelvis_rot, skeleton.offsets[up])
        hip = pelvis_pos + hip_off
        horiz2 = np.sum((ankles[:, s, [0, 2]] - hip[:, [0, 2]]) ** 2, axis=-1)
        d = max_reach * length
        if np.any(horiz2 >= d * d):
            raise ValueError(f"{side} ankle is too far from the hip horizontally to be reached at any pelvis height")
        allowed = np.minimum(allowed, ankles[:, s, 1] + np.sqrt(d * d - horiz2) - hip_off[:, 1])
    return y - smooth_envelope(np.maximum(y - allowed, 0.0), radius, loop)


def smooth_envelope(need: F, radius: int, loop: bool) -> F:
    """A smooth curve ``>= need`` everywhere (along axis 0): dilate by ``2·radius``, box-blur twice by ``radius``.

    Used to turn a per-frame correction (how far the pelvis must drop, how far an arm must
    swing out) into one that eases in and out over a few frames.
    """
    need = np.asarray(need, dtype=np.float64)
    if not need.any():
        return need.copy()
    mode = "wrap" if loop else "nearest"
    smooth = maximum_filter1d(need, size=4 * radius + 1, axis=0, mode=mode)
    for _ in range(2):
        smooth = uniform_filter1d(smooth, size=2 * radius + 1, axis=0, mode=mode)
    return np.maximum(smooth, need)
