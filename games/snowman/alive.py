"""Bringing a snowman to life: its rig, its locomotion, and the puppet entity.

Every snowman is a puppet: the same state machine and blend space as the default
puppet, played at the snowman's leg scale (:attr:`LocomotionPlayer.scale`) — the
clips' local rotations are kept and the root's height and travel are scaled, so its
feet stay planted on its shorter legs, and requests (speed, hips height) are read in
the clips' units, which is the lookup table measured on scaled clips (thesis §6.3:
"adapted to different environments and character dimensions"). Sharing the set also
poses every puppet and snowman in one batch.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from engine.ecs import Entity, World
from engine.render.components import Appearance
from engine.statemachine.puppet import PuppetTuning, spawn_puppet
from games.snowman.components import Snowman
from games.snowman.rig import SnowmanShape, leg_scale, snowman_skeleton

__all__ = ["bring_to_life", "snowman_tuning"]


def snowman_tuning(shape: SnowmanShape) -> PuppetTuning:
    """Behaviour thresholds scaled to the snowman's height."""
    s = leg_scale(shape)
    base = PuppetTuning()
    return replace(
        base,
        stand_height=base.stand_height * s,
        crouch_height=base.crouch_height * s,
        crouch_enter=base.crouch_enter * s,
        crouch_exit=base.crouch_exit * s,
        lift_limit=base.lift_limit * max(s, 0.5),
        max_speed=base.max_speed * s,
        flick_launch_speed=base.flick_launch_speed * np.sqrt(s),
        reach=base.reach + shape.bottom * 0.5,
        front=shape.bottom + 0.05,
        carry_max_radius=max(base.carry_max_radius, 0.8 * shape.bottom),
    )


def bring_to_life(world: World, shape: SnowmanShape, position: np.ndarray, heading: float, number: int) -> Entity:
    """Spawn a snowman puppet standing where its bottom ball was."""
    ground = np.array([position[0], 0.0, position[2]])
    return spawn_puppet(
        world,
        ground,
        heading,
        skeleton=snowman_skeleton(shape),
        library_key="humanoid",
        scale=leg_scale(shape),
        tuning=snowman_tuning(shape),
        name=f"snowman {number}",
        extra=(Snowman(shape, number), Appearance(color=(0.97, 0.98, 1.0), visible=False)),
    )
