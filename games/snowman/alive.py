"""Bringing a snowman to life: its rig, its locomotion set, and the puppet entity.

Every snowman is a puppet: the same state machine and blend space as the default
puppet, with clips scaled to its proportions — the clips' local rotations are
kept, the root's height and travel are scaled by the snowman's leg scale, so its
feet stay planted on its shorter legs — and its lookup table measured anew on
those clips (thesis §6.3: "adapted to different environments and character
dimensions").
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from engine.blend.locomotion import BlendLibrary
from engine.blend.puppet import build_locomotion
from engine.clip import Clip, RootMotion
from engine.clips import default_clips
from engine.ecs import Entity, World
from engine.render.components import Appearance
from engine.skeleton import Skeleton
from engine.statemachine.puppet import PuppetTuning, spawn_puppet
from games.snowman.components import Snowman
from games.snowman.rig import SnowmanShape, leg_scale, snowman_skeleton

__all__ = ["scaled_clips", "bring_to_life", "snowman_tuning"]


def scaled_clips(skeleton: Skeleton, scale: float) -> dict[str, Clip]:
    """The default clips on ``skeleton`` with root height and travel scaled by ``scale``."""
    out = {}
    for name, clip in default_clips().items():
        rm = clip.root_motion
        if rm is not None:
            rm = RootMotion(rm.translation * scale, rm.heading)
        out[name] = replace(clip, skeleton=skeleton, root=clip.root * scale, root_motion=rm)
    return out


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
    skeleton = snowman_skeleton(shape)
    key = f"snowman-{number}"
    library = world.resource(BlendLibrary)
    if key not in library:
        library.add(key, build_locomotion(scaled_clips(skeleton, leg_scale(shape)), density=15, dt=world.dt))
    ground = np.array([position[0], 0.0, position[2]])
    return spawn_puppet(
        world,
        ground,
        heading,
        skeleton=skeleton,
        library_key=key,
        tuning=snowman_tuning(shape),
        name=f"snowman {number}",
        extra=(Snowman(shape, number), Appearance(color=(0.97, 0.98, 1.0), visible=False)),
    )
