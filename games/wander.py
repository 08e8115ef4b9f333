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
from collections.abc import Sequence
from dataclasses import dataclass, field
from itertools import repeat
from typing import Any

import numpy as np
from numpy.typing import NDArray

from engine.app import App
from engine.batches import batch
from engine.blend.locomotion import LocomotionPlayer
from engine.columns import assignment_mark, columns, unassigned_since
from engine.components import Transform
from engine.ecs import World
from engine.ragdoll.components import Ragdoll, RagdollMode
from engine.rows import RowBlock, keep_in_rows, row_store
from engine.statemachine.puppet import Jumping, PuppetBody
from engine.statemachine.puppet.follow import rows_of, set_requests
from engine.statemachine.puppet.plugin import puppet_batch
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
    their positions, rotations and goals are columns (:mod:`engine.columns`); when their bodies are
    linked to the brain stage's row block (:mod:`engine.rows`), who is held and the headings are
    read and written in its arrays."""
    kept = batch(world, "wanderers", (Wanderer, PuppetBody), (Jumping, Ragdoll, Transform, LocomotionPlayer))
    wanderers, bodies, jumps, rds, transforms, players = kept.lists
    found = None if any(kept.missing) else row_store(world).rows(PuppetBody, bodies)
    if found is None:
        _wander(world, *_free_one_by_one(kept.lists), None, None)
        return
    block, rows = found
    own = row_store(world).block(Wanderer, wanderers)
    if own.stale:
        _wander(world, *_free_one_by_one(kept.lists), None, None)
        return
    n = len(bodies)
    ok = ~block.present["held_by"][rows]
    on_ground = row_store(world).block(Jumping, jumps)
    ok &= (np.fromiter(map(_AIR, jumps), np.float64, n) if on_ground.stale else on_ground.arrays["air"]) == 0.0
    ok &= _animated(own, rds)
    puppets = puppet_batch(world)
    whole = (
        None if puppets.missing[2] or row_store(world).owners(PuppetBody) is not puppets.lists[0] else puppets.lists[2]
    )
    player_rows = row_store(world).rows(LocomotionPlayer, players)
    if ok.all():
        _wander(world, wanderers, bodies, transforms, players, (block, rows), (own, _ALL), whole, player_rows)
        return
    free = np.flatnonzero(ok)
    if len(free):
        at = free.tolist()
        _wander(
            world,
            [wanderers[i] for i in at],
            [bodies[i] for i in at],
            [transforms[i] for i in at],
            [players[i] for i in at],
            (block, free if isinstance(rows, slice) else rows[free]),
            (own, free),
            whole,
            rows_of(player_rows, free),
        )


def _animated(own: RowBlock, rds: tuple[Ragdoll, ...]) -> NDArray[np.bool_]:
    """Which of the wanderers' ragdolls are animated (not falling, not limp): read from every ragdoll once, then kept
    (in the wanderers' row block) while no ragdoll's mode was assigned (:func:`engine.columns.assignment_mark`).
    Shared: read it, never change it."""
    kept = own.memo.get("animated")
    if kept is not None and kept[0] is rds and unassigned_since(kept[1]):
        found: NDArray[np.bool_] = kept[2]
        return found
    mark = assignment_mark(Ragdoll, ("mode",))
    animated = np.fromiter(map(operator.is_, map(_MODE, rds), repeat(RagdollMode.ANIMATED)), np.bool_, len(rds))
    own.memo["animated"] = (rds, mark, animated)
    return animated


def _free_one_by_one(lists: tuple[tuple[Any, ...], ...]) -> tuple[list[Any], list[Any], list[Any], list[Any]]:
    """The free wanderers' components, tested one by one (a batch with a missing component, or bodies not in rows)."""
    free = [
        i
        for i, (body, jump, rd, tr, player) in enumerate(zip(*lists[1:], strict=True))
        if body.held_by is None
        and (jump is None or jump.air == 0.0)
        and rd is not None
        and rd.mode is RagdollMode.ANIMATED
        and tr is not None
        and player is not None
    ]
    wanderers, bodies, _, _, transforms, players = ([c[i] for i in free] for c in lists)
    return wanderers, bodies, transforms, players


def _wander(
    world: World,
    wanderers: Sequence[Wanderer],
    bodies: Sequence[PuppetBody],
    transforms: Sequence[Transform],
    players: Sequence[LocomotionPlayer],
    block_rows: tuple[RowBlock, slice | NDArray[np.intp]] | None,
    wander_rows: tuple[RowBlock, slice | NDArray[np.intp]] | None,
    whole: tuple[Transform, ...] | None = None,
    player_rows: tuple[RowBlock, slice | NDArray[np.intp]] | None = None,
) -> None:
    """Steer the free wanderers given (row ``i`` of each list for one puppet; their rows of the bodies' and
    the wanderers' row blocks, if they are linked). ``whole`` (the transforms of the bodies' block, row for
    row) lets the positions and rotations be read and written in the brain stage's columns at the bodies'
    rows, instead of columns of the wanderers' own; with ``player_rows`` (the players' rows in their row
    block) the requested speeds are written there whole."""
    n = len(wanderers)
    if n == 0:
        return
    cols = columns(world)
    at = None if whole is None or block_rows is None else block_rows[1]
    if whole is None or at is None:
        pos = cols.get(Transform, "position").read(transforms)
    else:
        pos = cols.get(Transform, "position").read(whole)[at]
    if wander_rows is None:
        goal = np.array([w.goal for w in wanderers], dtype=np.float64).reshape(n, 3)
        pace = np.fromiter(map(_SPEED, wanderers), np.float64, n)
    else:
        goal = wander_rows[0].arrays["goal"][wander_rows[1]]
        pace = wander_rows[0].arrays["speed"][wander_rows[1]]
    err = goal - pos
    dist = np.hypot(err[:, 0], err[:, 2])
    if block_rows is None:
        heading = np.fromiter(map(_HEADING, bodies), np.float64, n)
    else:
        heading = block_rows[0].arrays["heading"][block_rows[1]]
    turn = (np.arctan2(err[:, 0], err[:, 2]) - heading + np.pi) % (2 * np.pi) - np.pi
    step = _TURN_RATE * world.dt
    heading = (heading + np.clip(turn, -step, step) + np.pi) % (2 * np.pi) - np.pi
    facing = np.maximum(np.cos(turn), 0.0)
    if whole is None or at is None:
        cols.get(Transform, "rotation").write(transforms, yaw_rotation(heading))
    else:  # every row's field is its view after the read; only the wanderers' rows change
        cols.get(Transform, "rotation").read(whole)[at] = yaw_rotation(heading)
    if block_rows is None:
        for body, h in zip(bodies, heading.tolist(), strict=True):
            body.heading = h
    else:
        block_rows[0].arrays["heading"][block_rows[1]] = heading
    set_requests(players, player_rows, pace * facing)
    for i in np.flatnonzero(dist < _REACHED).tolist():
        w = wanderers[i]
        w.goal = np.array(
            [
                *world.rng.uniform(-w.field_half, w.field_half, 1),
                0.0,
                *world.rng.uniform(-w.field_half, w.field_half, 1),
            ]
        )


keep_in_rows(Wanderer, speed=("float", (), False), goal=("vector", (3,), False))
"""A crowd's paces and goals are arrays (:mod:`engine.rows`): the steering reads them whole."""

_ALL = slice(None)
_HEADING = operator.attrgetter("heading")
_SPEED = operator.attrgetter("speed")
_AIR = operator.attrgetter("air")
_MODE = operator.attrgetter("mode")


def install_wander(app: App) -> None:
    """Plugin: :func:`wander_system` in the ``statemachine`` stage, after the brains."""
    app.add_system("statemachine", wander_system)
