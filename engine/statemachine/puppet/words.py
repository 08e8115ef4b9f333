"""What a puppet is doing, in the words a player would use ("walking", "fell: invalid jump").

The overlay used to print the state's name and the last events the brain saw
("#11 Ragdoll (jump_invalid)"), which kept a fall's reason on screen long after
the puppet was back up. Here the words come from the state the brain is in *now*
and, for a fall, from the transition that entered it, so the reason goes away with
the state. Reads the world only.

The overlay names a crowd's puppets every frame ("and 996 more: 587 walking, 395 running"):
:func:`describe_puppets` gives the same words for all of them at once, the gaits of those
walking or crouching (nearly all of a crowd) read from the row arrays their brains' states
and their bodies' ground velocities live in (:mod:`engine.rows`), the few others one by one.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from engine.arrays import F64
from engine.ecs import Entity, World
from engine.rows import RowBlock, row_store
from engine.statemachine.machine import Brain
from engine.statemachine.puppet.body import Jumping, JumpPhase, PuppetBody
from engine.statemachine.puppet.names import PuppetEvent, PuppetState

__all__ = ["describe_puppet", "describe_puppets", "RUN_FRACTION"]

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


def describe_puppets(
    world: World, entities: Sequence[Entity], brains: tuple[Brain, ...], bodies: tuple[PuppetBody | None, ...]
) -> list[str]:
    """:func:`describe_puppet` of every ``entities[i]`` with ``brains[i]`` and ``bodies[i]``, in order.

    Where the brains and bodies are in their row blocks (a crowd once the brain stage ran), the
    puppets walking or crouching get their gait from the arrays, with the same comparisons on the
    same numbers as :func:`_gait`; the others, and every puppet outside the blocks, one by one."""
    store = row_store(world)
    at_brains = store.rows(Brain, brains) if brains else None
    at_bodies = None if at_brains is None or None in bodies else store.rows(PuppetBody, bodies)
    if at_brains is None or at_bodies is None:
        return [describe_puppet(world, e, brain) for e, brain in zip(entities, brains, strict=True)]
    active = at_brains[0].arrays["active"][at_brains[1]]
    block, rows = at_bodies
    velocity = block.arrays["ground_velocity"][rows]
    still, top = (limit[rows] for limit in _speed_limits(block))
    speed = np.hypot(velocity[:, 0], velocity[:, 2])
    crouched = active == PuppetState.CROUCH
    moving = np.where(crouched, "crouch-walking", np.where(speed >= RUN_FRACTION * top, "running", "walking"))
    gait = np.where(speed < still, np.where(crouched, "crouching", "standing"), moving).tolist()
    on_feet = (crouched | (active == PuppetState.LOCOMOTION)).tolist()
    return [gait[i] if on_feet[i] else describe_puppet(world, entities[i], brains[i]) for i in range(len(brains))]


def _speed_limits(block: RowBlock) -> tuple[F64, F64]:
    """Per row of a block of bodies: its tuning's ``still_speed`` and ``max_speed``, derived once and kept
    with the block while no tuning is assigned (``RowBlock.objects_set``)."""
    kept = block.memo.get("speed limits")
    if kept is None or kept[0] != block.objects_set:
        tunings = block.arrays["tuning"]
        still = np.fromiter((t.still_speed for t in tunings), np.float64, len(tunings))
        top = np.fromiter((t.max_speed for t in tunings), np.float64, len(tunings))
        kept = block.memo["speed limits"] = (block.objects_set, still, top)
    return kept[1], kept[2]
