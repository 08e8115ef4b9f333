"""Recognising a snowman: two or three balls stacked, largest at the bottom.

A ball rests on another when its centre is above the other's, horizontally within
a fraction of the lower radius, and the gap between the surfaces is small. The
stack is read from the ground up; stacks of two or three balls with decreasing
radii are snowmen waiting to come alive.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["Ball", "find_snowmen", "resting_on"]


@dataclass(frozen=True)
class Ball:
    """A snowball as the rules see it."""

    entity: int
    center: NDArray[np.float64]
    radius: float


def resting_on(upper: Ball, lower: Ball, gap: float = 0.06, off_axis: float = 0.45) -> bool:
    """Whether ``upper`` sits on top of ``lower``."""
    d = np.asarray(upper.center) - np.asarray(lower.center)
    horizontal = float(np.hypot(d[0], d[2]))
    if d[1] <= 0 or horizontal > off_axis * lower.radius:
        return False
    return abs(float(np.linalg.norm(d)) - (upper.radius + lower.radius)) <= gap * (upper.radius + lower.radius)


def find_snowmen(balls: list[Ball], on_ground: float = 0.1) -> list[list[Ball]]:
    """Stacks of 2–3 balls, bottom first, radii decreasing upwards; each ball in one stack at most."""
    order = sorted(balls, key=lambda b: (float(b.center[1]), b.entity))
    used: set[int] = set()
    stacks: list[list[Ball]] = []
    for base in order:
        if base.entity in used or base.center[1] - base.radius > on_ground:
            continue
        stack = [base]
        while len(stack) < 3:
            above = [b for b in order if b.entity not in used and b not in stack and resting_on(b, stack[-1]) and b.radius < stack[-1].radius]
            if not above:
                break
            stack.append(min(above, key=lambda b: b.entity))
        if len(stack) >= 2:
            stacks.append(stack)
            used.update(b.entity for b in stack)
    return stacks
