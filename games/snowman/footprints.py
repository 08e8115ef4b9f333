"""Footprints in the snow where the puppets walk: display only, recorded per step.

A foot leaves a print when it comes down: its joint drops below a planted height (a
multiple of its capsule radius, so a snowman's scaled legs work too) after having been
lifted above a higher one (hysteresis, so a foot resting near the threshold does not
stamp a print every step). The print lies under the foot, pointing where the toes point.

It runs in the schedule (the ``rules`` stage, after FK) so that every step is seen, at
any frame rate, and a replay leaves the same prints; but :class:`Footprints` is
``SIM_STATE = False``: nothing in the simulation reads it and it is not hashed, so the
recordings' state hashes do not change. Old prints fade, as falling snow fills them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from engine import quat
from engine.components import Puppet, WorldPose
from engine.ecs import World
from engine.render.scene import RenderScene

__all__ = ["Footprints", "leave_footprints", "draw_footprints", "PLANTED", "LIFTED"]

PLANTED, LIFTED = 1.6, 2.0
"""A foot joint is down below ``PLANTED × radius`` above the ground, up above ``LIFTED × radius``."""
SAME_SPOT = 0.08
"""A foot put down within this many metres of its last print (stepping in place) leaves no new one."""
_FEET = ("l_foot", "r_foot")


@dataclass
class Footprints:
    """The latest ``capacity`` prints (a ring buffer) and whether each foot is down now."""

    SIM_STATE = False

    capacity: int = 600
    fade_start: float = 40.0
    """Seconds a print stays sharp before it starts to fill with snow."""
    fade_time: float = 30.0
    xz: NDArray[np.float64] = field(init=False)  # the ring buffer, ``capacity`` long (made by __post_init__)
    heading: NDArray[np.float64] = field(init=False)
    frame: NDArray[np.int64] = field(init=False)
    count: int = 0
    down: dict[tuple[int, int], bool] = field(default_factory=dict)
    last: dict[tuple[int, int], NDArray[np.float64]] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.xz = np.zeros((self.capacity, 2))
        self.heading = np.zeros(self.capacity)
        self.frame = np.full(self.capacity, -1, dtype=np.int64)

    def stamp(self, xz: NDArray[np.float64], heading: float, frame: int) -> None:
        """Add a print (over the oldest once full)."""
        i = self.count % self.capacity
        self.xz[i], self.heading[i], self.frame[i] = xz, heading, frame
        self.count += 1

    def visible(self, now: int, dt: float) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """``(xz [N,2], heading [N], strength [N])`` of the prints not yet filled."""
        used = self.frame >= 0
        age = (now - self.frame[used]) * dt
        strength = np.clip(1.0 - (age - self.fade_start) / self.fade_time, 0.0, 1.0)
        keep = strength > 0.0
        return self.xz[used][keep], self.heading[used][keep], strength[keep]


def leave_footprints(world: World) -> None:
    """Stamp a print for every foot that came down this step."""
    prints = world.try_resource(Footprints)
    if prints is None:
        return
    for e, puppet, wp in world.query(Puppet, WorldPose):
        sk = puppet.skeleton
        try:
            feet = [sk.index(name) for name in _FEET]
        except (KeyError, ValueError):
            continue
        for side, j in enumerate(feet):
            height, r = float(wp.positions[j, 1]), float(sk.radii[j])
            key = (int(e), side)
            was_down = prints.down.get(key, False)
            if was_down and height > LIFTED * r:
                prints.down[key] = False
            elif not was_down and height < PLANTED * r:
                prints.down[key] = True
                toe = quat.rotate(wp.rotations[j], sk.tips[j])
                centre = wp.positions[j, [0, 2]] + 0.5 * toe[[0, 2]]
                last = prints.last.get(key)
                if last is None or float(np.hypot(*(centre - last))) > SAME_SPOT:
                    prints.stamp(centre, float(np.arctan2(toe[2], toe[0])), world.frame)
                    prints.last[key] = centre


def draw_footprints(world: World, scene: RenderScene) -> None:
    """The prints still visible, as ground decals."""
    prints = world.try_resource(Footprints)
    if prints is None or prints.count == 0:
        return
    xz, heading, strength = prints.visible(world.frame, world.dt)
    if len(xz):
        scene.add_prints(xz, heading, strength=strength)
