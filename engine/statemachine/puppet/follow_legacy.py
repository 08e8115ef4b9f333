"""The locomotion follower of earlier rounds, kept only so ``bench motion`` can compare against it.

It asks for the stick's filtered speed plus a catch-up term, but switches at a hard
0.12 m: nearer than that the request is clamped to ``catch_up_gain · distance``. A
steady drag's lag sits right at that radius, so the request jumps between a walk and a
stroll several times a second and the feet skate (measured in ``bench motion``); it
also clamps at ``max_speed``, so a fast drag outruns the puppet and drops it. Select it
with ``PuppetTuning(controller="legacy")``; :mod:`~engine.statemachine.puppet.follow`
is what plays.
"""

from __future__ import annotations

import numpy as np

from engine.blend.locomotion import LocomotionPlayer
from engine.components import Transform
from engine.ecs import Entity, World
from engine.statemachine.puppet.body import PuppetBody
from engine.statemachine.puppet.senses import heading_vector, yaw_rotation

__all__ = ["follow_stick_legacy"]


def _wrap(angle: float) -> float:
    return float((angle + np.pi) % (2 * np.pi) - np.pi)


def follow_stick_legacy(
    world: World, entity: Entity, body: PuppetBody, player: LocomotionPlayer, speed_scale: float = 1.0
) -> None:
    """Steer toward the stick's ground point: set heading and requested speed (hard-switched)."""
    tr = world.get(entity, Transform)
    t = body.tuning
    if body.held_by is None:
        player.speed = 0.0
        return
    err = body.target - tr.position
    err[1] = 0.0
    dist = float(np.linalg.norm(err))
    chase = max(dist - t.follow_deadband, 0.0)
    wanted = 0.0 if chase <= 0.0 and body.speed < t.still_speed else body.speed + t.catch_up_gain * chase
    if dist > 0.12:
        goal = float(np.arctan2(err[0], err[2]))
        turn = _wrap(goal - body.heading)
        body.heading = _wrap(body.heading + float(np.clip(turn, -t.turn_rate * world.dt, t.turn_rate * world.dt)))
        facing = max(float(heading_vector(body.heading) @ (err / dist)), 0.0)
        wanted *= facing
    else:
        wanted = min(wanted, t.catch_up_gain * dist)
    tr.rotation = yaw_rotation(body.heading)
    player.speed = float(np.clip(wanted * speed_scale, 0.0, t.max_speed))
