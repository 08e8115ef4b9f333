"""The snowman game's own components and resources."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from games.snowman.rig import SnowmanShape

__all__ = ["Snowball", "Snowman", "SnowmanStats", "StackWatch", "Stacked"]


@dataclass
class Snowball:
    """A ball of snow; ``last`` is where it was last step (to measure rolling).

    ``snow`` is the exact radius the snow it picked up gives it; the physical radius
    (``Prop.radius``) follows in steps of ``GROWTH_STEP`` because every change of it
    re-derives the physics model's constants (and perturbs its solver).
    """

    last: NDArray[np.float64] = field(default_factory=lambda: np.full(3, np.nan))
    snow: float = 0.0


@dataclass
class Snowman:
    """A living snowman: the balls it was built from (its proportions)."""

    shape: SnowmanShape
    number: int = 1


@dataclass
class StackWatch:
    """Resource: how long each candidate stack (by its ball ids) has stood still, and how
    many two-ball stacks stand waiting for a head."""

    SIM_STATE = True
    frames: dict[tuple[int, ...], int] = field(default_factory=dict)
    headless: int = 0


@dataclass
class SnowmanStats:
    """Resource: the counter shown on screen."""

    SIM_STATE = True
    built: int = 0
    balls_started: int = 0


@dataclass
class Stacked:
    """A ball packed onto the ball ``on``: it stays centred on it (snow sticks to snow)."""

    on: int
