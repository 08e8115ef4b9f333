"""How a puppet state is declared and registered, and the columns its array guards read.

A state module exports one :class:`StateSpec`: its state (or states) and the
transitions it owns — the ways into it as well as out of it, so that adding a state
is one module plus its registration (``puppet_machine(extra=(my_module.SPEC,))``
for a game's own state, or a line in :data:`~engine.statemachine.puppet.machine.BUILT_IN`).

:class:`PuppetColumns` is what the brain system gathers once per step for every
puppet (row ``i`` is ``entities[i]``): the array guards of
:func:`~engine.statemachine.machine.step_machines` read it, so a crowd's common case
is decided over arrays, not puppet by puppet.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from engine.blend.locomotion import LocomotionPlayer
from engine.components import Transform
from engine.ecs import Entity, World
from engine.ik.system import IKRequest
from engine.rows import RowBlock
from engine.statemachine.machine import Rows, State, Transition
from engine.statemachine.puppet.body import Handling, PuppetBody

__all__ = ["PuppetColumns", "PuppetStateDef", "PuppetTransition", "StateSpec", "free_rows", "held_rows"]


@dataclass
class PuppetColumns:
    """Per-step columns over all puppets: the entities, their bodies, and who is held by a stick.

    The other components the array updates work on come along where the caller has them
    (kept by :func:`engine.batches.batch`), row ``i`` for ``entities[i]``, ``None`` in a list
    for a puppet without one; a list left ``None`` is looked up entity by entity."""

    entities: list[Entity]
    bodies: Sequence[PuppetBody]
    held: NDArray[np.bool_]
    transforms: Sequence[Transform] | None = None
    players: Sequence[LocomotionPlayer | None] | None = None
    handling: Sequence[Handling | None] | None = None
    ik: Sequence[IKRequest | None] | None = None
    block: RowBlock | None = None
    """The row block the bodies are linked to, row ``i`` for ``bodies[i]`` (:mod:`engine.rows`), if they are."""
    handling_block: RowBlock | None = None
    """The row block ``handling`` is linked to, if every puppet has one and they are."""
    player_rows: tuple[RowBlock, slice | NDArray[np.intp]] | None = None
    """Where ``players`` are in the locomotion players' row block (every puppet has one and all are in it): the
    requests an array update sets are written there whole (see :func:`player_rows`)."""


PuppetStateDef = State[PuppetColumns]
PuppetTransition = Transition[PuppetColumns]


@dataclass(frozen=True)
class StateSpec:
    """One state module's contribution to the puppet machine: its states and its transitions."""

    states: tuple[PuppetStateDef, ...]
    transitions: tuple[PuppetTransition, ...] = ()


def held_rows(world: World, columns: PuppetColumns, rows: Rows) -> NDArray[np.bool_]:
    """Array guard: the puppets a stick holds (every guard that reads the stick can only fire for them)."""
    return columns.held[rows]


def free_rows(world: World, columns: PuppetColumns, rows: Rows) -> NDArray[np.bool_]:
    """Array ``fits``: a puppet no stick holds certainly fits a ground state (it cannot be lifted or yanked)."""
    return ~columns.held[rows]
