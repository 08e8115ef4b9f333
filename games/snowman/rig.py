"""The snowman's rig: the puppet's skeleton with bone lengths fitted to its balls (thesis §6.3).

A snowman is the same 17-joint hierarchy as the default puppet, so it walks,
crouches, jumps and falls with the same state machine and blend space; only the
offsets differ. The bottom ball is the pelvis, the middle ball the chest, the top
ball the head: the neck length comes from the head size, the spine length from the
two lower balls, the legs are short stubs under the bottom ball and the arms are
twigs from the chest ball's sides.

A long spine bone would swing the chest ball stiffly, so the body is drawn along a
quadratic Bézier from pelvis to chest whose middle control point bends toward where
the chest would be if the snowman stood upright (Eq. 6.4, Fig. 6.8):
``p1 = (p_pelvis + (1 − b)·p_chest + b·p_up) / 2`` with ``b = 0.3``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from engine.humanoid import humanoid_skeleton
from engine.skeleton import Skeleton

__all__ = ["SnowmanShape", "snowman_skeleton", "bezier_spine", "spine_control_point", "BEND"]

BEND = 0.3


@dataclass(frozen=True)
class SnowmanShape:
    """Radii of the balls a snowman was built from, bottom to top (two or three balls)."""

    bottom: float
    middle: float | None
    head: float

    def __post_init__(self) -> None:
        radii = [r for r in (self.bottom, self.middle, self.head) if r is not None]
        if any(not np.isfinite(r) or r <= 0 for r in radii):
            raise ValueError(f"snowball radii must be positive, got {radii}")
        if sorted(radii, reverse=True) != radii:
            raise ValueError(f"a snowman is built largest ball at the bottom, got {radii}")

    @property
    def height(self) -> float:
        """Standing height from the ground to the top of the head."""
        return 2 * self.bottom + 2 * (self.middle or 0.0) + 2 * self.head


def snowman_skeleton(shape: SnowmanShape) -> Skeleton:
    """The humanoid hierarchy with offsets, tips and radii sized from the balls."""
    base = humanoid_skeleton()
    off = np.array(base.offsets)
    tips = np.array(base.tips)
    radii = np.array(base.radii)
    j = base.index
    rb, rh = shape.bottom, shape.head
    rm = shape.middle if shape.middle is not None else 0.0
    leg = 0.9 * rb  # hips at the bottom ball's centre, feet just under it
    off[j("hips")] = (0.0, leg, 0.0)
    # Pelvis -> chest: the lower two balls touch; spine is the first half, chest the second.
    torso = rb + rm if shape.middle is not None else rb * 0.8
    off[j("spine")] = (0.0, 0.5 * torso, 0.0)
    off[j("chest")] = (0.0, 0.5 * torso, 0.0)
    # Neck length from the head size: the head ball sits on the chest ball.
    neck = (rm if shape.middle is not None else 0.2 * rb) + rh
    off[j("neck")] = (0.0, 0.5 * neck, 0.0)
    off[j("head")] = (0.0, 0.5 * neck, 0.0)
    tips[j("head")] = (0.0, rh, 0.0)
    shoulder = 0.9 * (rm if shape.middle is not None else rb)
    arm = 0.55 * shape.height * 0.5
    for side, sx in (("l", 1.0), ("r", -1.0)):
        off[j(f"{side}_upper_arm")] = (sx * shoulder, 0.1 * torso, 0.0)
        off[j(f"{side}_lower_arm")] = (0.0, -0.5 * arm, 0.0)
        off[j(f"{side}_hand")] = (0.0, -0.5 * arm, 0.0)
        tips[j(f"{side}_hand")] = (0.0, -0.15 * arm, 0.0)
        off[j(f"{side}_upper_leg")] = (sx * 0.35 * rb, -0.1 * leg, 0.0)
        off[j(f"{side}_lower_leg")] = (0.0, -0.45 * leg, 0.0)
        off[j(f"{side}_foot")] = (0.0, -0.45 * leg, 0.0)
        tips[j(f"{side}_foot")] = (0.0, -0.05 * leg, 0.35 * rb)
    radii[j("hips")] = rb
    radii[j("chest")] = rm if shape.middle is not None else 0.5 * rb
    radii[j("head")] = rh
    radii[[j("spine"), j("neck")]] = 0.5 * radii[j("chest")]
    for name in ("upper_arm", "lower_arm", "hand"):
        radii[[j(f"l_{name}"), j(f"r_{name}")]] = 0.02 + 0.02 * rb
    for name in ("upper_leg", "lower_leg", "foot"):
        radii[[j(f"l_{name}"), j(f"r_{name}")]] = 0.25 * rb
    return Skeleton(base.names, base.parents, off, tips, radii)


def spine_control_point(p_pelvis: NDArray[np.float64], p_chest: NDArray[np.float64], p_up: NDArray[np.float64], b: float = BEND) -> NDArray[np.float64]:
    """Eq. 6.4: the Bézier's middle control point, ``(p_pelvis + (1−b)·p_chest + b·p_up)/2``."""
    return (np.asarray(p_pelvis) + (1.0 - b) * np.asarray(p_chest) + b * np.asarray(p_up)) / 2.0


def bezier_spine(
    p_pelvis: NDArray[np.float64],
    p_chest: NDArray[np.float64],
    p_up: NDArray[np.float64],
    t: NDArray[np.float64] | float,
    b: float = BEND,
) -> NDArray[np.float64]:
    """Points of the quadratic Bézier pelvis → chest at parameters ``t`` (``[...,3]``, batched)."""
    p0 = np.asarray(p_pelvis, dtype=np.float64)
    p2 = np.asarray(p_chest, dtype=np.float64)
    p1 = spine_control_point(p0, p2, p_up, b)
    t = np.asarray(t, dtype=np.float64)[..., None]
    return (1 - t) ** 2 * p0 + 2 * (1 - t) * t * p1 + t**2 * p2
