"""Components the renderer reads: how an entity looks (``Appearance``) and what solid it is (``Shape``).

``Shape`` is simulation state: a snowball's radius grows as it rolls, and game rules and
physics read it, so it is hashed like any component. ``Appearance`` is display only
(colour, the focus outline, visibility) and declares ``SIM_STATE = False``, so toggling
an outline or recolouring a puppet never changes a replay's state hashes.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["Appearance", "Shape", "SHAPE_KINDS"]

# kind -> number of size values: sphere (radius), capsule (radius, half_length), box (half extents)
SHAPE_KINDS: dict[str, int] = {"sphere": 1, "capsule": 2, "box": 3}


@dataclass
class Appearance:
    """Display settings of an entity: sRGB ``color`` in [0,1], focus ``outline``, ``visible``.

    ``joint_colors`` optionally colours a puppet per joint (``[J,3]``); a bone takes the
    colour of the joint it starts from.
    """

    SIM_STATE: ClassVar[bool] = False

    color: tuple[float, float, float] = (0.85, 0.45, 0.3)
    outline: bool = False
    visible: bool = True
    joint_colors: NDArray[np.float64] | None = None

    def __post_init__(self) -> None:
        c = np.asarray(self.color, dtype=np.float64)
        if c.shape != (3,) or not np.all((c >= 0) & (c <= 1)):
            raise ValueError(f"color must be 3 values in [0, 1], got {self.color!r}")
        self.color = (float(c[0]), float(c[1]), float(c[2]))
        if self.joint_colors is not None:
            jc = np.asarray(self.joint_colors, dtype=np.float64)
            if jc.ndim != 2 or jc.shape[1] != 3:
                raise ValueError(f"joint_colors must be [J,3], got shape {jc.shape}")
            self.joint_colors = jc


@dataclass
class Shape:
    """A rigid solid placed by the entity's ``Transform`` (scaled by ``Transform.scale``).

    ``size`` per ``kind``: ``sphere`` ``[radius]``; ``capsule`` ``[radius, half_length]``
    along the local Y axis; ``box`` ``[hx, hy, hz]`` half extents.
    """

    kind: str = "sphere"
    size: NDArray[np.float64] = field(default_factory=lambda: np.array([0.25]))

    def __post_init__(self) -> None:
        if self.kind not in SHAPE_KINDS:
            raise ValueError(f"shape kind must be one of {', '.join(SHAPE_KINDS)}, got {self.kind!r}")
        size = np.atleast_1d(np.asarray(self.size, dtype=np.float64)).reshape(-1).copy()
        if len(size) != SHAPE_KINDS[self.kind]:
            raise ValueError(f"a {self.kind} needs {SHAPE_KINDS[self.kind]} size values, got {len(size)}")
        if not np.all(np.isfinite(size)) or np.any(size < 0):
            raise ValueError(f"shape size must be finite and non-negative, got {size}")
        self.size = size

    @classmethod
    def sphere(cls, radius: float) -> Shape:
        """A sphere of ``radius``."""
        return cls("sphere", np.array([radius], dtype=np.float64))

    @classmethod
    def capsule(cls, radius: float, half_length: float) -> Shape:
        """A capsule along local Y: segment ``±half_length``, then ``radius`` around it."""
        return cls("capsule", np.array([radius, half_length], dtype=np.float64))

    @classmethod
    def box(cls, half_extents: ArrayLike) -> Shape:
        """A box with ``half_extents`` ``[3]``."""
        return cls("box", np.asarray(half_extents, dtype=np.float64))

    @property
    def radius(self) -> float:
        """Radius of a sphere or capsule (snowballs grow through this)."""
        if self.kind == "box":
            raise AttributeError("a box has half extents, not a radius")
        return float(self.size[0])

    @radius.setter
    def radius(self, value: float) -> None:
        if self.kind == "box":
            raise AttributeError("a box has half extents, not a radius")
        if not (np.isfinite(value) and value >= 0):
            raise ValueError(f"radius must be finite and non-negative, got {value}")
        self.size[0] = float(value)
