"""Locomotion and Crouch: the puppet walks, runs and crouches where the stick leads it.

Both states drive the same blend space (thesis Fig. 6.3): the stick's ground speed
becomes the requested root speed, resolved to blend parameters by the IDW lookup
table; the stick's height becomes the hips height. The puppet follows the stick's
ground point through the locomotion control (:mod:`~engine.statemachine.puppet.follow`:
the stick's velocity plus a smooth catch-up, through a critically damped spring),
turning toward where it is led at a bounded rate, so the clip's root motion — not a
teleport — carries it and its feet do not slide.

A crowd is mostly puppets walking in Locomotion with no stick: their guards are
decided over arrays (a guard of a ground state can only fire for a held puppet) and
:func:`update_locomotion_batch` updates them in one pass.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from engine.blend.locomotion import LocomotionPlayer
from engine.columns import assignment_mark, unassigned_since
from engine.columns import columns as engine_columns
from engine.components import Transform
from engine.ecs import Entity, World
from engine.ik.foot_lock import FootLock
from engine.ik.system import IKRequest
from engine.rows import RowBlock
from engine.statemachine.machine import Brain, Rows
from engine.statemachine.puppet.body import Handling, PuppetBody
from engine.statemachine.puppet.follow import drag_reach, follow_released, follow_velocity, rows_of, tuning_columns
from engine.statemachine.puppet.follow_legacy import follow_stick_legacy
from engine.statemachine.puppet.names import PuppetState
from engine.statemachine.puppet.spec import (
    PuppetColumns,
    PuppetStateDef,
    PuppetTransition,
    StateSpec,
    free_rows,
    held_rows,
)

__all__ = [
    "SPEC",
    "follow_stick",
    "lifted",
    "locomotion_fits",
    "update_crouch",
    "update_locomotion",
    "update_locomotion_batch",
    "wants_crouch",
    "wants_stand",
]


def follow_stick(
    world: World,
    entity: Entity,
    body: PuppetBody,
    player: LocomotionPlayer,
    speed_scale: float = 1.0,
    lead_band: float = 0.02,
) -> None:
    """Steer toward the stick's ground point: set heading and requested speed (the tuning's controller).

    The legacy controller comes as it was: without the leg IK's foot locks either."""
    ik = world.try_get(entity, IKRequest)
    if ik is not None:
        ik.foot_lock.enabled = body.tuning.controller != "legacy"
    if body.tuning.controller == "legacy":
        follow_stick_legacy(world, entity, body, player, speed_scale)
    else:
        follow_velocity(world, entity, body, player, speed_scale, lead_band)


def lifted(body: PuppetBody) -> bool:
    """Held clearly above standing height: no ground state fits (the ragdoll takes it)."""
    return body.held_by is not None and body.target_height > body.tuning.stand_height + body.tuning.lift_limit


def locomotion_fits(world: World, entity: Entity, brain: Brain) -> bool:
    """Ground states fit unless the puppet is lifted or yanked far beyond its stride."""
    body = world.get(entity, PuppetBody)
    if body.held_by is None:
        return True
    tr = world.get(entity, Transform)
    reach = body.tuning.drag_limit if body.tuning.controller == "legacy" else drag_reach(body)
    far = float(np.linalg.norm((body.target - tr.position)[[0, 2]])) > reach
    return not lifted(body) and not far


def wants_crouch(world: World, entity: Entity, brain: Brain) -> bool:
    """The stick holds the hips below the crouch threshold."""
    body = world.get(entity, PuppetBody)
    return body.held_by is not None and body.target_height < body.tuning.crouch_enter


def wants_stand(world: World, entity: Entity, brain: Brain) -> bool:
    """Released, or the stick is back above the crouch's exit height (hysteresis)."""
    body = world.get(entity, PuppetBody)
    return body.held_by is None or body.target_height > body.tuning.crouch_exit


def _ground_ik(world: World, entity: Entity) -> None:
    ik = world.try_get(entity, IKRequest)
    if ik is not None:
        ik.grounding = True
        ik.sphere_centre, ik.sphere_radius = None, 0.0


def update_locomotion(world: World, entity: Entity, brain: Brain) -> None:
    """Idle / walk / run: stand tall (a slight dip allowed) and follow the stick."""
    body = world.get(entity, PuppetBody)
    player = world.get(entity, LocomotionPlayer)
    t = body.tuning
    standing = body.held_by is None or body.target_height >= t.crouch_exit
    if standing:  # standing up ends the "leave it there" of a put-down (object_states)
        world.get(entity, Handling).left = None
    player.height = None if standing else float(np.clip(body.target_height, t.crouch_enter, t.stand_height))
    follow_stick(world, entity, body, player)
    _ground_ik(world, entity)


def update_crouch(world: World, entity: Entity, brain: Brain) -> None:
    """Crouch idle / crouch walk: the hips go as low as the stick holds them."""
    body = world.get(entity, PuppetBody)
    player = world.get(entity, LocomotionPlayer)
    t = body.tuning
    player.height = float(np.clip(body.target_height, t.crouch_height, t.crouch_exit))
    # Crouched, the stick is being lowered notch by notch, and each wheel notch slides the held
    # point out along the cursor's ray and back: it must lead by the dead band to make a stride.
    follow_stick(world, entity, body, player, lead_band=t.follow_deadband)
    _ground_ik(world, entity)


def update_locomotion_batch(world: World, columns: PuppetColumns, rows: Rows) -> None:
    """:func:`update_locomotion` for many puppets: those no stick holds, with the spring control, in one pass.

    When the bodies are linked to a row block (:mod:`engine.rows`) who is held and who runs the
    legacy controller are read from its arrays, and the spring works on them in place."""
    bodies = columns.bodies
    block = columns.block
    fast: list[int] = []
    if block is not None and not block.stale:
        slow = block.present["held_by"][rows] | tuning_columns(block)[0][rows]
        fast_rows = rows[~slow]
        for i in rows[slow].tolist():
            update_locomotion(world, columns.entities[i], world.get(columns.entities[i], Brain))
        fast = fast_rows.tolist()
    else:
        for i in rows.tolist():
            body = bodies[i]
            if body.held_by is None and body.tuning.controller != "legacy":
                fast.append(i)
            else:
                update_locomotion(world, columns.entities[i], world.get(columns.entities[i], Brain))
    if not fast:
        return
    entities = columns.entities
    every = len(fast) == len(entities)
    handling = _rows_of(world, Handling, columns.handling, entities, fast, every)
    players = _rows_of(world, LocomotionPlayer, columns.players, entities, fast, every)
    requests = _rows_of(world, IKRequest, columns.ik, entities, fast, every)
    transforms = _rows_of(world, Transform, columns.transforms, entities, fast, every)
    hb = columns.handling_block
    if hb is not None and not hb.stale:
        hb.present["left"][_ALL if every else fast] = False  # standing
    else:
        for h in handling:
            h.left = None  # standing
    _stand_requests(block, requests)
    fast_bodies = bodies if every else [bodies[i] for i in fast]
    linked = block is not None and not block.stale
    block_rows = (block, _ALL if every else np.asarray(fast, dtype=np.intp)) if linked and block is not None else None
    player_rows = columns.player_rows if every else rows_of(columns.player_rows, np.asarray(fast, dtype=np.intp))
    follow_released(
        world.dt,
        fast_bodies,
        transforms,
        players,
        engine_columns(world),
        block_rows,
        stand=True,
        player_rows=player_rows,
    )


_ALL = slice(None)


def _stand_requests(block: RowBlock | None, requests: Sequence[IKRequest | None]) -> None:
    """Ground the IK requests of puppets that stand: feet locked, grounding on, no sphere to hold.

    A crowd walking free asks this of the same requests step after step, and nothing else
    assigns those fields meanwhile: with the bodies' row ``block`` the batch of requests and where
    the fields' assignment logs stood after the last pass are kept (:func:`engine.columns.assignment_mark`),
    and while no such field was assigned since, on any request, the values are still in place."""
    kept = None if block is None or block.stale else block.memo.get("stand requests")
    if kept is not None and kept[0] is requests and unassigned_since(kept[1]) and unassigned_since(kept[2]):
        return
    for ik in requests:
        if ik is not None:
            ik.foot_lock.enabled = True
            ik.grounding = True
            ik.sphere_centre, ik.sphere_radius = None, 0.0
    if block is not None and not block.stale:
        block.memo["stand requests"] = (
            requests,
            assignment_mark(IKRequest, _STAND_FIELDS),
            assignment_mark(FootLock, ("enabled",)),
        )


_STAND_FIELDS = ("grounding", "sphere_centre", "sphere_radius", "foot_lock")


def _rows_of(
    world: World, ctype: type, kept: Sequence[Any] | None, entities: list[Entity], rows: list[int], every: bool
) -> Sequence[Any]:
    """The ``ctype`` components of ``rows``: from the list the caller kept, else looked up (``None`` if missing)."""
    if kept is None:
        store: Mapping[Entity, Any] = world.components(ctype)
        return [store.get(entities[i]) for i in rows]
    return kept if every else [kept[i] for i in rows]


_LOCOMOTION: PuppetStateDef = PuppetStateDef(
    PuppetState.LOCOMOTION,
    update=update_locomotion,
    fits=locomotion_fits,
    batch_update=update_locomotion_batch,
    batch_fits=free_rows,
    description="idle / walk / run from the blend space; follows the stick",
)
_CROUCH: PuppetStateDef = PuppetStateDef(
    PuppetState.CROUCH,
    update=update_crouch,
    fits=locomotion_fits,
    description="crouch idle / crouch walk; hips as low as the stick holds them",
)

SPEC = StateSpec(
    states=(_LOCOMOTION, _CROUCH),
    transitions=(
        PuppetTransition(
            PuppetState.LOCOMOTION,
            PuppetState.CROUCH,
            guard=wants_crouch,
            batch_guard=held_rows,
            priority=5,
            crossfade=0.25,
            label="lowered",
        ),
        PuppetTransition(
            PuppetState.CROUCH, PuppetState.LOCOMOTION, guard=wants_stand, priority=5, crossfade=0.25, label="raised"
        ),
    ),
)
"""Locomotion and Crouch, and the ways between them."""
