"""Wandering: puppets nobody holds walk to random points of the field at their own pace.

A crowd needs puppets that move without a stick. After the brains have run (a puppet
nobody holds asks for speed 0), :func:`wander_system` steers every :class:`Wanderer`
that is on the ground and not held toward its goal at a bounded turn rate and asks
its locomotion for the wanderer's own speed; a reached goal is replaced by a new
random point from the world's seeded generator, so a crowd is deterministic. The
steering is batched over all wanderers: a crowd of a hundred is one numpy pass.
"""

from __future__ import annotations

import operator
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from engine.app import App
from engine.batches import batch
from engine.blend.locomotion import LocomotionPlayer
from engine.columns import columns
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
    """Steer every free wanderer toward its goal; pick a new goal when one is reached.

    The wanderers' component lists are kept between structural changes (:mod:`engine.batches`),
    their positions, rotations and goals are columns (:mod:`engine.columns`)."""
    kept = batch(world, "wanderers", (Wanderer, PuppetBody), (Jumping, Ragdoll, Transform, LocomotionPlayer))
    free = [
        i
        for i, (body, jump, rd, tr, player) in enumerate(zip(*kept.lists[1:], strict=True))
        if body.held_by is None
        and (jump is None or jump.air == 0.0)
        and rd is not None
        and rd.mode is RagdollMode.ANIMATED
        and tr is not None
        and player is not None
    ]
    if not free:
        return
    if len(free) == len(kept.entities):
        wanderers, bodies, _, _, transforms, players = kept.lists
    else:
        wanderers, bodies, _, _, transforms, players = ([c[i] for i in free] for c in kept.lists)
    n = len(free)
    cols = columns(world)
    pos = cols.get(Transform, "position").read(transforms)
    goal = cols.get(Wanderer, "goal").read(wanderers)
    err = goal - pos
    dist = np.hypot(err[:, 0], err[:, 2])
    heading = np.fromiter(map(_HEADING, bodies), np.float64, n)
    turn = (np.arctan2(err[:, 0], err[:, 2]) - heading + np.pi) % (2 * np.pi) - np.pi
    step = _TURN_RATE * world.dt
    heading = (heading + np.clip(turn, -step, step) + np.pi) % (2 * np.pi) - np.pi
    facing = np.maximum(np.cos(turn), 0.0)
    cols.get(Transform, "rotation").write(transforms, yaw_rotation(heading))
    speeds = (np.fromiter(map(_SPEED, wanderers), np.float64, n) * facing).tolist()
    for body, player, h, v in zip(bodies, players, heading.tolist(), speeds, strict=True):
        body.heading = h
        player.speed = v
    for i in np.flatnonzero(dist < _REACHED).tolist():
        w = wanderers[i]
        w.goal = np.array(
            [
                *world.rng.uniform(-w.field_half, w.field_half, 1),
                0.0,
                *world.rng.uniform(-w.field_half, w.field_half, 1),
            ]
        )


_HEADING = operator.attrgetter("heading")
_SPEED = operator.attrgetter("speed")


def install_wander(app: App) -> None:
    """Plugin: :func:`wander_system` in the ``statemachine`` stage, after the brains."""
    app.add_system("statemachine", wander_system)
