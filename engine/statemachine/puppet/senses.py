"""What a puppet perceives each step: who holds it, where the stick wants it, what is near.

The context of the state machine (thesis §6.2.2) is the environment — the ground
and the objects around the puppet — and the MotionStick. The stick holds a puppet
by its anchor (the hips, ``Grabbable.offset``); the anchor the stick asks for is
``tip + R_stick · grab_offset``. Its ground projection is where the puppet should
stand, its height is the hips height asked for (lower: crouch; much higher: the
puppet is held in the air).

:func:`sense_all` does it for every puppet at once: the momentum over arrays, the
holders from one pass over the sticks, and only the held puppets one by one.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from engine import quat
from engine.columns import columns
from engine.components import Stick, Transform
from engine.ecs import Entity, World
from engine.ragdoll.components import Prop
from engine.rows import row_store
from engine.statemachine.puppet.body import PuppetBody
from engine.statemachine.puppet.spec import PuppetColumns

__all__ = ["holder", "wanted_anchor", "sense", "heading_vector", "prop_in_front", "yaw_rotation", "sense_all"]

from engine.arrays import F64 as F

_UP = np.array([0.0, 1.0, 0.0])


def holder(world: World, entity: Entity) -> tuple[Entity, Stick] | None:
    """The controller whose stick holds ``entity`` (the lowest id if several do)."""
    for e, stick in world.query(Stick):
        if stick.grabbed == entity:
            return e, stick
    return None


def wanted_anchor(stick: Stick) -> F:
    """Where the stick wants the held anchor: its tip plus the kept relative offset."""
    return stick.tip + quat.rotate(stick.orientation, stick.grab_offset)


def heading_vector(heading: float) -> F:
    """Unit ground vector of a heading angle (0 = +Z, positive toward +X)."""
    return np.array([np.sin(heading), 0.0, np.cos(heading)])


def yaw_rotation(heading: float | F) -> F:
    """The rotation about +Y of a heading angle (``[4]``), or of an array of them (``[n, 4]``).

    For a 1-D array it is :func:`engine.quat.from_axis_angle` about ``+Y`` written out, in half
    the numpy calls (a crowd's facing every step) and with the same bits: the axis is exactly
    ``(0, 1, 0)``, so its ``x`` and ``z`` parts are ``sin · 0.0`` (keeping the sign of zero)
    and its ``y`` part ``sin · 1.0 = sin``."""
    if isinstance(heading, np.ndarray) and heading.ndim == 1 and heading.dtype == np.float64:
        half = 0.5 * heading
        s = np.sin(half)
        out = np.empty((len(heading), 4))
        out[:, 0] = np.cos(half)
        out[:, 2] = s
        out[:, 1] = out[:, 3] = s * 0.0
        return out
    return quat.from_axis_angle(_UP, heading)


def sense(world: World, entity: Entity, body: PuppetBody) -> Stick | None:
    """Refresh ``body``'s view of the stick (and its own momentum); returns the holding stick, if any."""
    pos = world.get(entity, Transform).position
    if body.last_position is not None:
        body.ground_velocity = (pos - body.last_position) * np.array([1.0, 0.0, 1.0]) / world.dt
    body.last_position = np.array(pos, dtype=np.float64)
    held = holder(world, entity)
    if held is None:
        body.held_by = None
        body.speed = 0.0
        body.lead = np.zeros(3)
        return None
    return _sense_stick(body, *held)


def _sense_stick(body: PuppetBody, controller: Entity, stick: Stick) -> Stick:
    body.held_by = controller
    anchor = wanted_anchor(stick)
    body.target = np.array([anchor[0], 0.0, anchor[2]])
    body.target_height = float(anchor[1])
    body.speed = float(np.hypot(stick.velocity[0], stick.velocity[2]))
    body.lead = np.array([stick.velocity[0], 0.0, stick.velocity[2]])
    return stick


def sense_all(
    world: World,
    entities: list[Entity],
    bodies: Sequence[PuppetBody],
    transforms: Sequence[Transform] | None = None,
) -> PuppetColumns:
    """:func:`sense` for every puppet at once (the same numbers); the columns the array guards read.

    ``transforms`` (row ``i`` for ``entities[i]``) saves looking them up. The bodies are linked to
    a row block (:mod:`engine.rows`; kept while ``bodies`` is the same tuple): once every puppet
    has a ``last_position``, ``ground_velocity``, ``last_position``, ``lead``, ``held_by`` and
    ``speed`` are written whole in the block's arrays, no puppet touched; before that (a puppet's
    first step) puppet by puppet."""
    n = len(entities)
    sticks: dict[Entity, tuple[Entity, Stick]] = {}
    for e, stick in world.query(Stick):  # entity order: the lowest id holds, as in holder()
        if stick.grabbed is not None:
            sticks.setdefault(stick.grabbed, (e, stick))
    if transforms is None:
        transforms = [world.get(e, Transform) for e in entities]
    block = row_store(world).block(PuppetBody, bodies if isinstance(bodies, tuple) else tuple(bodies)) if n else None
    if block is not None and not block.stale and block.present["last_position"].all():
        a = block.arrays
        pos = columns(world).get(Transform, "position").read(transforms)
        a["ground_velocity"][...] = (pos - a["last_position"]) * _GROUND / world.dt
        a["last_position"][...] = pos
        a["lead"][...] = 0.0
        a["speed"][...] = 0.0
        block.present["held_by"][...] = False
    else:
        _sense_first(world, bodies, transforms)
        block = None
    held = np.zeros(n, dtype=bool)
    for e, by in sticks.items():
        if e in entities:
            i = entities.index(e)
            held[i] = True
            _sense_stick(bodies[i], *by)
    return PuppetColumns(entities, bodies, held, transforms, block=block)


_GROUND = np.array([1.0, 0.0, 1.0])


def _sense_first(world: World, bodies: Sequence[PuppetBody], transforms: Sequence[Transform]) -> None:
    """The momentum and rest values of :func:`sense_all` when some puppet has no ``last_position`` yet."""
    n = len(bodies)
    pos = np.array([tr.position for tr in transforms], dtype=np.float64).reshape(n, 3)
    known = [i for i, b in enumerate(bodies) if b.last_position is not None]
    if known:
        last = np.array([bodies[i].last_position for i in known], dtype=np.float64)
        velocity = (pos[known] - last) * _GROUND / world.dt
        for j, i in enumerate(known):
            bodies[i].ground_velocity = velocity[j]
    zeros = np.zeros((n, 3))
    for i, body in enumerate(bodies):
        body.last_position = pos[i]
        body.held_by, body.speed, body.lead = None, 0.0, zeros[i]


def prop_in_front(
    world: World, entity: Entity, body: PuppetBody, reach: float, max_radius: float | None = None, spread: float = 0.25
) -> Entity | None:
    """The nearest free prop whose surface is within ``reach`` in front of the puppet, its centre at most
    ``spread`` (or its radius) to the side of the heading."""
    tr = world.get(entity, Transform)
    forward = heading_vector(body.heading)
    best, best_d = None, np.inf
    for e, prop, ptr in world.query(Prop, Transform):
        if prop.carried or (max_radius is not None and prop.radius > max_radius):
            continue
        d = ptr.position - tr.position
        d[1] = 0.0
        ahead = float(d @ forward)
        side = float(np.linalg.norm(d - ahead * forward))
        gap = float(np.linalg.norm(d)) - prop.radius
        if ahead > 0.0 and side < max(prop.radius, spread) and gap < reach and gap < best_d:
            best, best_d = e, gap
    return best
