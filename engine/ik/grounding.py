"""Foot placement on uneven ground (like FinalIK's Grounder), via two-bone IK on the legs.

Clips are authored on flat ground at ``y = 0``. For each foot we read how high its
sole is above that flat ground in the clip, look up the real ground under it
(``ground(x, z) -> (height, normal)``), and ask the leg to put the sole that high
above the real ground, with the foot turned to the ground's slope (fully when
planted, fading out as the foot lifts). The pelvis moves by the lowest foot's
height change, so a foot stepping into a dip is reached by lowering the body
rather than over-stretching a leg, and the other knee bends instead.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from engine import quat
from engine.ik._vec import path_fk, rotate
from engine.ik.two_bone import two_bone_ik
from engine.pose import Pose
from engine.skeleton import Skeleton

__all__ = ["GroundQuery", "PlaneGround", "HeightfieldGround", "Leg", "HUMANOID_LEGS", "ground_feet"]

F = NDArray[np.float64]
GroundQuery = Callable[[F, F], tuple[F, F]]


@dataclass(frozen=True)
class PlaneGround:
    """A plane through ``point`` with ``normal`` (a slope, or flat ground with the default normal)."""

    point: tuple[float, float, float] = (0.0, 0.0, 0.0)
    normal: tuple[float, float, float] = (0.0, 1.0, 0.0)

    def __call__(self, x: ArrayLike, z: ArrayLike) -> tuple[F, F]:
        """Height ``[...]`` and unit normal ``[...,3]`` under ``(x, z)``."""
        n = np.asarray(self.normal, dtype=np.float64)
        n = n / np.linalg.norm(n)
        if n[1] < 1e-6:
            raise ValueError("ground plane must not be vertical")
        p = np.asarray(self.point, dtype=np.float64)
        x, z = np.asarray(x, dtype=np.float64), np.asarray(z, dtype=np.float64)
        h = p[1] - (n[0] * (x - p[0]) + n[2] * (z - p[2])) / n[1]
        return h, np.broadcast_to(n, h.shape + (3,)).copy()


@dataclass(frozen=True)
class HeightfieldGround:
    """A regular grid of heights (bilinear), ``heights[i, k]`` at ``x = x0 + i·cell``, ``z = z0 + k·cell``."""

    heights: F
    cell: float
    x0: float = 0.0
    z0: float = 0.0

    def __call__(self, x: ArrayLike, z: ArrayLike) -> tuple[F, F]:
        """Height and normal under ``(x, z)``; points off the grid take the nearest edge."""
        h = np.asarray(self.heights, dtype=np.float64)
        fx = np.clip((np.asarray(x, dtype=np.float64) - self.x0) / self.cell, 0.0, h.shape[0] - 1.000001)
        fz = np.clip((np.asarray(z, dtype=np.float64) - self.z0) / self.cell, 0.0, h.shape[1] - 1.000001)
        i, k = np.floor(fx).astype(int), np.floor(fz).astype(int)
        u, v = fx - i, fz - k
        h00, h10, h01, h11 = h[i, k], h[i + 1, k], h[i, k + 1], h[i + 1, k + 1]
        height = (1 - u) * (1 - v) * h00 + u * (1 - v) * h10 + (1 - u) * v * h01 + u * v * h11
        dhdx = ((1 - v) * (h10 - h00) + v * (h11 - h01)) / self.cell
        dhdz = ((1 - u) * (h01 - h00) + u * (h11 - h10)) / self.cell
        n = np.stack([-dhdx, np.ones_like(dhdx), -dhdz], axis=-1)
        return height, n / np.linalg.norm(n, axis=-1, keepdims=True)


@dataclass(frozen=True)
class Leg:
    """A leg's joints, the knee's pole direction in the hips' frame, and the sole in the foot's frame."""

    upper: str
    lower: str
    foot: str
    sole: tuple[float, float, float]
    knee_forward: tuple[float, float, float] = (0.0, 0.0, 1.0)


# The humanoid's sole centre: under the ankle, half-way to the toe tip (tips: (0, -0.05, 0.15)).
HUMANOID_LEGS: tuple[Leg, ...] = (
    Leg("l_upper_leg", "l_lower_leg", "l_foot", (0.0, -0.05, 0.075)),
    Leg("r_upper_leg", "r_lower_leg", "r_foot", (0.0, -0.05, 0.075)),
)


def ground_feet(
    skeleton: Skeleton,
    pose: Pose,
    ground: GroundQuery,
    legs: tuple[Leg, ...] = HUMANOID_LEGS,
    *,
    offsets: ArrayLike | None = None,
    align_height: float = 0.25,
    contact_height: float = 0.03,
    max_pelvis_shift: float = 0.5,
    weight: float = 1.0,
) -> F:
    """Plant one puppet's feet on ``ground`` in place; returns the pelvis height change applied.

    Args:
        skeleton, pose: the puppet and its animated pose (one puppet; root is world space).
        ground: ``ground(x, z) -> (height, normal)``.
        legs: which limbs are legs and where their soles are.
        align_height: sole height (m) above which a lifted foot no longer follows the slope.
        contact_height: sole height (m) below which the foot counts as planted (fully aligned).
        max_pelvis_shift: largest pelvis move (m), either way.
        weight: 0..1 blend of the whole effect.
    """
    if not 0.0 <= weight <= 1.0:
        raise ValueError("weight must lie in 0..1")
    idx = [(skeleton.index(leg.upper), skeleton.index(leg.lower), skeleton.index(leg.foot)) for leg in legs]
    sole_local = np.array([leg.sole for leg in legs], dtype=np.float64)
    feet_pos, feet_rot = [], []
    for _, _, f in idx:
        wp, wr = path_fk(skeleton, pose.root, pose.rotations, f, offsets)
        feet_pos.append(wp[f]), feet_rot.append(wr[f])
    ankle, qfoot = np.array(feet_pos), np.array(feet_rot)
    sole = ankle + rotate(qfoot, sole_local)
    clip_height = sole[:, 1]  # authored on flat ground at y = 0
    height, normal = ground(sole[:, 0], sole[:, 2])
    height, normal = np.asarray(height, dtype=np.float64), np.asarray(normal, dtype=np.float64)
    if not (np.all(np.isfinite(height)) and np.all(np.isfinite(normal))):
        raise ValueError("ground query returned non-finite values")
    # Turn each foot to the slope, fading out as it lifts.
    planted = np.clip((align_height - clip_height) / (align_height - contact_height), 0.0, 1.0) * weight
    tilt = quat.slerp(quat.identity(len(legs)), quat.between(np.array([0.0, 1.0, 0.0]), normal), planted)
    new_rot = quat.mul(tilt, qfoot)
    new_sole = np.stack([sole[:, 0], height * weight + clip_height, sole[:, 2]], axis=-1)
    targets = new_sole - rotate(new_rot, sole_local)
    # Pelvis: follow the lowest foot (negative into dips, positive onto steps).
    shift = float(np.clip(np.min(targets[:, 1] - ankle[:, 1]), -max_pelvis_shift, max_pelvis_shift))
    pose.root[1] += shift
    for leg, (u, lo, f), tgt, frot in zip(legs, idx, targets, new_rot, strict=True):
        wp, wr = path_fk(skeleton, pose.root, pose.rotations, lo, offsets)
        pole = wp[lo] + rotate(wr[int(skeleton.parents[u])], np.asarray(leg.knee_forward, dtype=np.float64))
        two_bone_ik(skeleton, pose, (u, lo, f), tgt, pole, end_rotation=frot, offsets=offsets)
    return np.float64(shift)
