"""A state that is not built in: Wave — the puppet stops and waves for half a second.

It is what a game adding a state writes: this one module (its typed component, its
callbacks, the transitions into and out of it, one ``StateSpec``) and one registration,
``puppet_machine(extra=(SPEC,))``. Loaded by the tests as ordinary test code.
"""

from __future__ import annotations

from dataclasses import dataclass

from engine.blend.locomotion import LocomotionPlayer
from engine.ecs import Entity, World
from engine.statemachine.machine import Brain
from engine.statemachine.puppet.names import PuppetState
from engine.statemachine.puppet.spec import PuppetStateDef, PuppetTransition, StateSpec

WAVE = "Wave"
WAVE_EVENT = "wave"
WAVE_TIME = 0.5


@dataclass
class Waving:
    """The Wave state's data: seconds spent waving."""

    timer: float = 0.0


def _enter(world: World, entity: Entity, brain: Brain) -> None:
    world.get(entity, Waving).timer = 0.0


def _update(world: World, entity: Entity, brain: Brain) -> None:
    world.get(entity, LocomotionPlayer).speed = 0.0
    world.get(entity, Waving).timer += world.dt


def _done(world: World, entity: Entity, brain: Brain) -> bool:
    return world.get(entity, Waving).timer >= WAVE_TIME


SPEC = StateSpec(
    states=(PuppetStateDef(WAVE, enter=_enter, update=_update, description="stop and wave"),),
    transitions=(
        PuppetTransition(PuppetState.LOCOMOTION, WAVE, event=WAVE_EVENT, priority=1, crossfade=0.1),
        PuppetTransition(WAVE, PuppetState.LOCOMOTION, guard=_done, crossfade=0.2, label="waved"),
    ),
)
