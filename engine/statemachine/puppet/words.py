"""What a puppet is doing, in the words a player would use ("walking", "fell: invalid jump").

The overlay used to print the state's name and the last events the brain saw
("#11 Ragdoll (jump_invalid)"), which kept a fall's reason on screen long after
the puppet was back up. Here the words come from the state the brain is in *now*
and, for a fall, from the transition that entered it, so the reason goes away with
the state. Reads the world only.
"""

from __future__ import annotations

import numpy as np

from engine.ecs import Entity, World
from engine.statemachine.machine import Brain
from engine.statemachine.puppet.body import Jumping, JumpPhase, PuppetBody
from engine.statemachine.puppet.names import PuppetEvent, PuppetState

__all__ = ["describe_puppet", "RUN_FRACTION"]

RUN_FRACTION = 0.55
"""Ground speed, as a fraction of the puppet's top speed, from which it reads as running."""

_FIXED: dict[str, str] = {
    PuppetState.LAND: "landing",
    PuppetState.GET_UP: "getting up",
    PuppetState.PICK_UP: "picking up a ball",
    PuppetState.CARRY: "carrying a ball",
    PuppetState.PUT_DOWN: "putting a ball down",
    PuppetState.ROLL_SNOWBALL: "rolling a snowball",
}


def _gait(body: PuppetBody, crouched: bool) -> str:
    speed = float(np.hypot(body.ground_velocity[0], body.ground_velocity[2]))
    if speed < body.tuning.still_speed:
        return "crouching" if crouched else "standing"
    if crouched:
        return "crouch-walking"
    return "running" if speed >= RUN_FRACTION * body.tuning.max_speed else "walking"


def _fall(brain: Brain, body: PuppetBody, jump: Jumping | None) -> str:
    """Why the puppet is limp: the reason of the transition into the ragdoll, if it says one,
    else whether the stick holds it up."""
    entered = next((t for t in reversed(brain.trace) if t.target == brain.active), None)
    if entered is not None and entered.reason == PuppetEvent.JUMP_INVALID:
        why = None if jump is None or jump.invalid is None else jump.invalid.value
        return "fell: invalid jump" + (f" ({why})" if why else "")
    return "hanging from the stick" if body.held_by is not None else "fell over"


def describe_puppet(world: World, entity: Entity, brain: Brain) -> str:
    """A few words for what the puppet ``entity`` with ``brain`` is doing this step."""
    state = brain.active
    body = world.try_get(entity, PuppetBody)
    if state in _FIXED or body is None:
        return _FIXED.get(state, state.lower() or "starting")
    if state in (PuppetState.LOCOMOTION, PuppetState.CROUCH):
        return _gait(body, crouched=state == PuppetState.CROUCH)
    jump = world.try_get(entity, Jumping)
    if state == PuppetState.JUMP:
        return "getting ready to jump" if jump is not None and jump.phase is JumpPhase.ANTICIPATION else "in the air"
    if state == PuppetState.RAGDOLL:
        return _fall(brain, body, jump)
    return state.lower()
