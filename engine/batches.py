"""Batches: the component lists of a query's entities, gathered once and kept until a structural change.

A system over a crowd starts every step by gathering, puppet by puppet, the components it
works on (``[world.get(e, Transform) for e in entities]``, one list per type). Between
structural changes (a spawn, a despawn, a component added, removed or replaced) those
lists are the same objects step after step, and gathering them again is Python work per
puppet for nothing. :func:`batch` keeps them: it hands back the lists gathered last time
for as long as the world's cached query results it was built from (the query of the
required types, and one query per optional type) are still the very same list objects —
the world drops those on every structural change that touches their types
(:meth:`World.query`), so a kept batch can never be stale. The cache holds the query lists
it compares against, so their ids are never reused while it keeps them. While the world's
count of structural changes (:attr:`World.structure`) has not moved since, not even the
queries are asked again.

Only membership is cached: the values in the components are read fresh by the caller.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterable, Mapping, Sequence, Sized
from dataclasses import dataclass
from itertools import repeat
from typing import Any

from engine.ecs import Entity, World

__all__ = ["Batch", "Batches", "assign", "batch"]


@dataclass(frozen=True)
class Batch:
    """The entities of a query and, per type, their components (``None`` where an optional one is missing).

    Attributes:
        entities: the entities having every required type, in entity order.
        lists: one tuple per type, required types first, then the optional ones, row ``i`` for ``entities[i]``
            (tuples: the same object step after step, so a column of :mod:`engine.columns` knows them by identity
            and does not compare them row by row).
        missing: per list, whether some entity lacks that component (its row is ``None``).
    """

    entities: list[Entity]
    lists: tuple[tuple[Any, ...], ...]
    missing: tuple[bool, ...]


class Batches:
    """Resource: the kept batches, by key. Not simulation state (membership only, rebuilt on demand)."""

    SIM_STATE = False

    def __init__(self) -> None:
        self._kept: dict[object, tuple[tuple[list[Any], ...], Batch]] = {}
        # Per key: the world, its structure count and the types it was last checked at.
        self._at: dict[object, tuple[World, int, tuple[type, ...], tuple[type, ...]]] = {}

    def get(self, world: World, key: object, required: tuple[type, ...], optional: tuple[type, ...] = ()) -> Batch:
        """The batch of ``required`` (with ``optional`` beside it) named ``key``, rebuilt if the world changed."""
        at = self._at.get(key)
        if at is not None and at[0] is world and at[1] == world.structure and at[2] == required and at[3] == optional:
            return self._kept[key][1]
        sources = (world.query(*required), *(world.query(t) for t in optional))
        kept = self._kept.get(key)
        if kept is not None and len(kept[0]) == len(sources) and all(map(_same, kept[0], sources)):
            self._at[key] = (world, world.structure, required, optional)
            return kept[1]
        rows = sources[0]
        entities = [r[0] for r in rows]
        lists = [tuple([r[k] for r in rows]) for k in range(1, len(required) + 1)]
        for t in optional:
            store: Mapping[Entity, Any] = world.components(t)
            lists.append(tuple([store.get(e) for e in entities]))
        made = Batch(entities, tuple(lists), tuple(any(c is None for c in comps) for comps in lists))
        self._kept[key] = (sources, made)
        self._at[key] = (world, world.structure, required, optional)
        return made


def _same(a: object, b: object) -> bool:
    return a is b


def batch(world: World, key: object, required: tuple[type, ...], optional: tuple[type, ...] = ()) -> Batch:
    """The world's kept batch named ``key`` (see the module docstring; the resource is inserted on first use)."""
    found = world.try_resource(Batches)
    if found is None:
        found = Batches()
        world.insert_resource(found)
    return found.get(world, key, required, optional)


def assign(objects: Sequence[Any], name: str, values: Iterable[Any]) -> None:
    """``objects[i].<name> = values[i]`` for every row, in row order: what a ``for`` loop over a crowd's components
    does, with the loop in C (a crowd's per-step speeds; each assignment still goes through the attribute's
    descriptor, if it has one). ``values`` must have a value for every object (a sized one is checked).

    Raises:
        ValueError: ``values`` has another length than ``objects``.
    """
    if isinstance(values, Sized) and len(values) != len(objects):
        raise ValueError(f"{len(values)} values of {name} for {len(objects)} objects")
    setter = map(setattr, objects, repeat(name, len(objects)), values)
    deque(setter, maxlen=0)
