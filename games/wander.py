"""Wandering: puppets nobody holds walk to random points of the field at their own pace.

A crowd needs puppets that move without a stick. After the brains have run (a puppet
nobody holds asks for speed 0), :func:`wander_system` steers every :class:`Wanderer`
that is on the ground and not held toward its goal at a bounded turn rate and asks
its locomotion for the wanderer's own speed; a reached goal is replaced by a new
random point from the world's seeded generator, so a crowd is deterministic. The
steering is batched over all wanderers: a crowd of a hundred is one numpy pass.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from engine.app import App
from engine.blend.locomotion import LocomotionPlayer
from engine.components import Transform
from engine.ecs import World
from engine.ragdoll.components import Ragdoll, RagdollMode
from engine.statemachine.puppet import Jumping, PuppetBody
from engine.statemachine.puppet.senses import yaw_rotation

__all__ = ["Wanderer", "wander_system", "install_wander"]

_REACHED = 0.5  # m: a goal this close is reached
_TURN_RATE = 2.5  # rad/s


@dataclass
class Wanderer:
    """A puppet that walks on its own: its pace (m/s), its goal and the field's half size (m)."""

    speed: float = 1.0
    goal: NDArray[np.float64] = field(default_factory=lambda: np.zeros(3))
    field_half: float = 8.0


def wander_system(world: World) -> None:
    """Steer every free wanderer toward its goal; pick a new goal when one is reached."""
    rows = [
        (w, body, tr, player)
        for e, w, body in world.query(Wanderer, PuppetBody)
        if body.held_by is None
        and ((jump := world.try_get(e, Jumping)) is None or jump.air == 0.0)
        and (rd := world.try_get(e, Ragdoll)) is not None
        and rd.mode is RagdollMode.ANIMATED
        and (tr := world.try_get(e, Transform)) is not None
        and (player := world.try_get(e, LocomotionPlayer)) is not None
    ]
    if not rows:
        return
    pos = np.array([r[2].position for r in rows])
    goal = np.array([r[0].goal for r in rows])
    err = goal - pos
    dist = np.hypot(err[:, 0], err[:, 2])
    heading = np.array([r[1].heading for r in rows])
    turn = (np.arctan2(err[:, 0], err[:, 2]) - heading + np.pi) % (2 * np.pi) - np.pi
    step = _TURN_RATE * world.dt
    heading = (heading + np.clip(turn, -step, step) + np.pi) % (2 * np.pi) - np.pi
    facing = np.maximum(np.cos(turn), 0.0)
    rotation = yaw_rotation(heading)
    for i, (w, body, tr, player) in enumerate(rows):
        body.heading = float(heading[i])
        tr.rotation = rotation[i]
        player.speed = float(w.speed * facing[i])
        if dist[i] < _REACHED:
            w.goal = np.array(
                [
                    *world.rng.uniform(-w.field_half, w.field_half, 1),
                    0.0,
                    *world.rng.uniform(-w.field_half, w.field_half, 1),
                ]
            )


def install_wander(app: App) -> None:
    """Plugin: :func:`wander_system` in the ``statemachine`` stage, after the brains."""
    app.add_system("statemachine", wander_system)
