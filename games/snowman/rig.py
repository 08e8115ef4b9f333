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

from engine.humanoid import HIP_HEIGHT as HUMAN_HIPS
from engine.humanoid import humanoid_skeleton
from engine.skeleton import Skeleton

__all__ = [
    "SnowmanShape",
    "snowman_skeleton",
    "bezier_spine",
    "spine_control_point",
    "leg_scale",
    "middle_ball_parameter",
    "BEND",
    "HUMAN_HIPS",
]

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
    """The humanoid hierarchy with offsets, tips and radii sized from the balls.

    The hips joint is the bottom ball's centre; the chest joint sits on top of the
    middle ball (where the head rests and the twig arms attach); the middle ball's
    centre lies on the Bézier spine between them (:func:`middle_ball_parameter`); the
    head joint is the head ball's centre, so the neck is as long as the head is big.
    The legs are the human legs scaled to the bottom ball (:func:`leg_scale`), so the
    human clips, scaled by the same factor, keep their feet planted.
    """
    base = humanoid_skeleton()
    s = leg_scale(shape)
    off = np.array(base.offsets)
    tips = np.array(base.tips)
    radii = np.array(base.radii)
    j = base.index
    rb, rh = shape.bottom, shape.head
    rm = shape.middle or 0.0
    off[j("hips")] = (0.0, HUMAN_HIPS * s, 0.0)
    spine = rb + 2.0 * rm if shape.middle is not None else rb
    off[j("spine")] = (0.0, 0.5 * spine, 0.0)
    off[j("chest")] = (0.0, 0.5 * spine, 0.0)
    off[j("neck")] = (0.0, 0.5 * rh, 0.0)
    off[j("head")] = (0.0, 0.5 * rh, 0.0)
    tips[j("head")] = (0.0, rh, 0.0)
    body = rm if shape.middle is not None else rb
    arm = 0.9 * body + 0.15
    for side, sx in (("l", 1.0), ("r", -1.0)):
        off[j(f"{side}_upper_arm")] = (sx * 0.75 * body, -0.45 * body, 0.0)
        off[j(f"{side}_lower_arm")] = (0.0, -0.5 * arm, 0.0)
        off[j(f"{side}_hand")] = (0.0, -0.5 * arm, 0.0)
        tips[j(f"{side}_hand")] = (0.0, -0.12 * arm, 0.0)
        for leg in ("upper_leg", "lower_leg", "foot"):
            off[j(f"{side}_{leg}")] = base.offsets[j(f"{side}_{leg}")] * s
        tips[j(f"{side}_foot")] = base.tips[j(f"{side}_foot")] * s
    radii[j("hips")] = rb
    radii[j("chest")] = 0.35 * body
    radii[j("head")] = rh
    radii[[j("spine"), j("neck")]] = 0.35 * body
    for name in ("upper_arm", "lower_arm", "hand"):
        radii[[j(f"l_{name}"), j(f"r_{name}")]] = 0.018 + 0.01 * rb
    for name in ("upper_leg", "lower_leg", "foot"):
        radii[[j(f"l_{name}"), j(f"r_{name}")]] = base.radii[j(f"l_{name}")] * s * 1.3
    return Skeleton(base.names, base.parents, off, tips, radii)


def leg_scale(shape: SnowmanShape) -> float:
    """How much shorter than the human's a snowman's legs are: the bottom ball sits on them."""
    return 0.8 * shape.bottom / HUMAN_HIPS + 0.12


def middle_ball_parameter(shape: SnowmanShape) -> float:
    """Where on the pelvis→chest Bézier the middle ball's centre lies (3-ball snowmen)."""
    if shape.middle is None:
        return 1.0
    return (shape.bottom + shape.middle) / (shape.bottom + 2.0 * shape.middle)


def spine_control_point(
    p_pelvis: NDArray[np.float64], p_chest: NDArray[np.float64], p_up: NDArray[np.float64], b: float = BEND
) -> NDArray[np.float64]:
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
