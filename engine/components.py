"""Components shared across packages: what one layer writes and a higher one reads.

The engine defines them so that it never imports ``input/`` or ``games/``
(DESIGN: imports go downwards). ``input/motionstick.py`` writes :class:`Stick`; the
puppet states read it. Animation writes :class:`LocalPose`; FK turns it into
:class:`WorldPose`, keeping the previous step for render interpolation.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from engine import quat
from engine.skeleton import Skeleton

__all__ = ["Transform", "Stick", "Puppet", "LocalPose", "WorldPose", "Grabbable", "Name", "Obstacle"]


def _vec3() -> NDArray[np.float64]:
    return np.zeros(3)


def _quat() -> NDArray[np.float64]:
    return quat.identity()


@dataclass
class Name:
    """A human-readable label (debug overlay, logs)."""

    value: str


@dataclass
class Transform:
    """Position, rotation (w,x,y,z) and uniform scale of a rigid thing (prop, camera target)."""

    position: NDArray[np.float64] = field(default_factory=_vec3)
    rotation: NDArray[np.float64] = field(default_factory=_quat)
    scale: float = 1.0


@dataclass
class Grabbable:
    """Marks an entity the MotionStick may grab.

    The pick sphere of ``radius`` sits at ``offset`` in the entity's ``Transform`` frame
    (a puppet is held at its hips, not at its feet): that point is the *anchor* the
    stick's tip holds.
    """

    radius: float = 0.5
    kind: str = "puppet"
    offset: NDArray[np.float64] = field(default_factory=_vec3)

    def anchor(self, transform: Transform) -> NDArray[np.float64]:
        """World position of the held point."""
        return transform.position + quat.rotate(transform.rotation, self.offset)


@dataclass
class Obstacle:
    """A vertical cylinder standing on the entity's ``Transform`` position (the MotionStick stops at it)."""

    radius: float = 0.5
    height: float = 2.0


@dataclass
class Stick:
    """The MotionStick as the simulation sees it (thesis §6.2.1).

    The controller sits at ``pivot`` and points along ``direction``; the tip is
    ``length`` along it (shortened where it would enter the ground). While an entity
    is grabbed, ``grab_offset``/``grab_rotation`` hold the grabbed thing's pose
    relative to the tip, so the stick's length and relative rotation are kept.
    """

    pivot: NDArray[np.float64] = field(default_factory=_vec3)
    direction: NDArray[np.float64] = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    orientation: NDArray[np.float64] = field(default_factory=_quat)
    length: float = 3.0
    tip: NDArray[np.float64] = field(default_factory=_vec3)
    tip_rotation: NDArray[np.float64] = field(default_factory=_quat)
    velocity: NDArray[np.float64] = field(default_factory=_vec3)
    touching: bool = False
    grabbed: int | None = None
    focus: int | None = None
    grab_offset: NDArray[np.float64] = field(default_factory=_vec3)
    grab_rotation: NDArray[np.float64] = field(default_factory=_quat)
    just_grabbed: bool = False
    released: int | None = None  # the entity let go this step
    flick: bool = False
    connected: bool = True
    source: str = "mouse"


@dataclass
class Puppet:
    """A character: its skeleton asset and per-puppet bone offsets (snowmen differ)."""

    skeleton: Skeleton = field(metadata={"hash": False})
    offsets: NDArray[np.float64] | None = None
    kind: str = "human"

    def joint_offsets(self) -> NDArray[np.float64]:
        """Offsets in use: the puppet's own or the skeleton's."""
        return self.skeleton.offsets if self.offsets is None else self.offsets


@dataclass
class LocalPose:
    """The pose animation produced this step: world root position, world heading and local rotations."""

    root: NDArray[np.float64]
    rotations: NDArray[np.float64]


@dataclass
class WorldPose:
    """FK output, with the previous step kept so rendering can interpolate."""

    positions: NDArray[np.float64]
    rotations: NDArray[np.float64]
    prev_positions: NDArray[np.float64] = field(metadata={"hash": False})
    prev_rotations: NDArray[np.float64] = field(metadata={"hash": False})

    def interpolated(self, alpha: float) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Positions and rotations ``alpha`` of the way from the previous to this step."""
        pos = self.prev_positions + alpha * (self.positions - self.prev_positions)
        return pos, quat.nlerp(self.prev_rotations, self.rotations, alpha)
