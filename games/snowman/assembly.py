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

__all__ = ["Ball", "find_snowmen", "resting_matrix"]


@dataclass(frozen=True)
class Ball:
    """A snowball as the rules see it."""

    entity: int
    center: NDArray[np.float64]
    radius: float


def resting_matrix(
    centers: NDArray[np.float64], radii: NDArray[np.float64], gap: float = 0.06, off_axis: float = 0.45
) -> NDArray[np.bool_]:
    """``[N, N]`` booleans: entry ``[u, l]`` says ball ``u`` sits on top of ball ``l``.

    On top means: centre above, horizontally within ``off_axis`` of the lower radius, and
    the distance between centres within ``gap`` (a fraction of the radii sum) of touching.
    All pairs at once: the rules ask every step, for every ball.
    """
    c = np.asarray(centers, dtype=np.float64).reshape(-1, 3)
    r = np.asarray(radii, dtype=np.float64).reshape(-1)
    d = c[:, None, :] - c[None, :, :]
    horizontal = np.hypot(d[..., 0], d[..., 2])
    touch = r[:, None] + r[None, :]
    return (
        (d[..., 1] > 0)
        & (horizontal <= off_axis * r[None, :])
        & (np.abs(np.linalg.norm(d, axis=-1) - touch) <= gap * touch)
    )


def find_snowmen(balls: list[Ball], on_ground: float = 0.1) -> list[list[Ball]]:
    """Stacks of 2–3 balls, bottom first, radii decreasing upwards; each ball in one stack at most."""
    if len(balls) < 2:
        return []
    centers = np.array([b.center for b in balls], dtype=np.float64)
    radii = np.array([b.radius for b in balls], dtype=np.float64)
    on = resting_matrix(centers, radii) & (radii[:, None] < radii[None, :])
    # Who rests on each ball, from one pass over the matrix (the rules ask every step, for every ball).
    resting_on: dict[int, list[int]] = {}
    for upper, lower in zip(*np.nonzero(on), strict=True):
        resting_on.setdefault(int(lower), []).append(int(upper))
    heights = centers[:, 1].tolist()
    grounded = (~(centers[:, 1] - radii > on_ground)).tolist()
    order = sorted(range(len(balls)), key=lambda i: (heights[i], balls[i].entity))
    used: set[int] = set()
    stacks: list[list[Ball]] = []
    for base in order:
        if base in used or not grounded[base]:
            continue
        stack = [base]
        while len(stack) < 3:
            above = [i for i in resting_on.get(stack[-1], ()) if i not in used and i not in stack]
            if not above:
                break
            stack.append(min(above, key=lambda i: balls[i].entity))
        if len(stack) >= 2:
            stacks.append([balls[i] for i in stack])
            used.update(stack)
    return stacks
