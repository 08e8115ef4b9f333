"""A small entity-component-system core: the world every system reads and writes.

Why our own rather than esper: we need three things esper does not promise —
iteration in entity-id order (determinism: replays must hash the same), a
state digest over every simulation component, and structural changes that wait
for a stage boundary. The whole core stays small and typed, in esper's spirit.

- Entities are ints, handed out in increasing order and never reused.
- Components are plain objects (dataclasses), at most one of each type per entity.
- Resources are singletons keyed by type (the clock, the input frame, assets).
- Queries return ``(entity, comp_a, comp_b, …)`` tuples sorted by entity id and are
  cached until a structural change touches one of their component types.
- ``queue_spawn`` / ``queue_despawn`` / ``queue_add`` / ``queue_remove`` defer a change to
  the next :meth:`World.flush`, which the app calls between stages, so a system never
  sees the set it iterates change under it.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping
from types import MappingProxyType
from typing import Any, TypeVar, overload

import numpy as np

__all__ = ["World", "Entity"]

Entity = int
T = TypeVar("T")
A = TypeVar("A")
B = TypeVar("B")
C = TypeVar("C")


class World:
    """Entities, their components, resources, a seeded RNG and the frame counter.

    Args:
        seed: seeds the world's only random generator (determinism rule).
        dt: the fixed simulation step in seconds.
    """

    def __init__(self, seed: int = 0, dt: float = 1.0 / 60.0) -> None:
        self.seed = seed
        self.dt = dt
        self.frame = 0
        self.rng = np.random.default_rng(seed)
        self._next_entity = 1
        self._components: dict[type, dict[Entity, Any]] = {}
        self._entities: dict[Entity, set[type]] = {}
        self._resources: dict[type, Any] = {}
        self._query_cache: dict[tuple[type, ...], list[tuple[Any, ...]]] = {}
        self.structure = 0
        """Counts structural changes (spawn, despawn, a component added, replaced or removed): what is kept
        from the world's membership (:mod:`engine.batches`) holds while it is unchanged."""
        self._pending: list[Callable[[], None]] = []

    # -- time -------------------------------------------------------------------------
    @property
    def time(self) -> float:
        """Simulation time, ``frame * dt``; never the wall clock."""
        return self.frame * self.dt

    # -- entities ---------------------------------------------------------------------
    def spawn(self, *components: Any) -> Entity:
        """Create an entity now with the given components and return its id."""
        e = self._next_entity
        self._next_entity += 1
        self._entities[e] = set()
        for c in components:
            self.add(e, c)
        return e

    def despawn(self, entity: Entity) -> None:
        """Remove an entity and all its components now (no error if already gone)."""
        for t in self._entities.pop(entity, set()):
            del self._components[t][entity]
            self._invalidate(t)

    def alive(self, entity: Entity) -> bool:
        """Whether the entity exists."""
        return entity in self._entities

    def entities(self) -> list[Entity]:
        """All live entity ids in increasing order."""
        return sorted(self._entities)

    # -- components -------------------------------------------------------------------
    def add(self, entity: Entity, component: Any) -> None:
        """Attach (or replace) a component on an entity now."""
        if entity not in self._entities:
            raise KeyError(f"entity {entity} does not exist")
        t = type(component)
        store = self._components.setdefault(t, {})
        if entity not in store:
            self._entities[entity].add(t)
            self._invalidate(t)
            store[entity] = component
        else:
            store[entity] = component
            self._invalidate(t)

    def remove(self, entity: Entity, ctype: type) -> None:
        """Detach a component type from an entity now (no error if absent)."""
        store = self._components.get(ctype)
        if store is not None and entity in store:
            del store[entity]
            self._entities[entity].discard(ctype)
            self._invalidate(ctype)

    def get(self, entity: Entity, ctype: type[T]) -> T:
        """The entity's component of that type; ``KeyError`` names what is missing."""
        try:
            return self._components[ctype][entity]
        except KeyError:
            raise KeyError(f"entity {entity} has no {ctype.__name__}") from None

    def try_get(self, entity: Entity, ctype: type[T]) -> T | None:
        """The component or ``None``."""
        return self._components.get(ctype, {}).get(entity)

    def components(self, ctype: type[T]) -> Mapping[Entity, T]:
        """Every component of that type by entity: a live, read-only view, for a system that looks up
        one optional component per row of a batch (``.get(e)``) without a call per lookup."""
        return MappingProxyType(self._components.setdefault(ctype, {}))

    def has(self, entity: Entity, ctype: type) -> bool:
        """Whether the entity has a component of that type."""
        return entity in self._components.get(ctype, {})

    def components_of(self, entity: Entity) -> list[Any]:
        """Every component of an entity, ordered by type name (stable for hashing)."""
        types = sorted(self._entities.get(entity, ()), key=lambda t: (t.__module__, t.__qualname__))
        return [self._components[t][entity] for t in types]

    def component_types(self) -> list[type]:
        """The component types at least one entity has, ordered by type name (stable for hashing)."""
        return sorted(
            (t for t, store in self._components.items() if store), key=lambda t: (t.__module__, t.__qualname__)
        )

    # -- queries ----------------------------------------------------------------------
    @overload
    def query(self, a: type[A], /) -> list[tuple[Entity, A]]: ...
    @overload
    def query(self, a: type[A], b: type[B], /) -> list[tuple[Entity, A, B]]: ...
    @overload
    def query(self, a: type[A], b: type[B], c: type[C], /) -> list[tuple[Entity, A, B, C]]: ...
    @overload
    def query(self, *ctypes: type) -> list[tuple[Any, ...]]: ...

    def query(self, *ctypes: type) -> list[tuple[Any, ...]]:
        """Entities having all ``ctypes``, as ``(entity, *components)`` sorted by entity id."""
        cached = self._query_cache.get(ctypes)
        if cached is not None:
            return cached
        stores = [self._components.get(t, {}) for t in ctypes]
        smallest = min(stores, key=len) if stores else {}
        result = [(e, *(s[e] for s in stores)) for e in sorted(smallest) if all(e in s for s in stores)]
        self._query_cache[ctypes] = result
        return result

    def single(self, *ctypes: type) -> tuple[Any, ...] | None:
        """The first match of a query, or ``None`` (for one-of-a-kind entities)."""
        rows = self.query(*ctypes)
        return rows[0] if rows else None

    def _invalidate(self, ctype: type) -> None:
        self.structure += 1
        for key in [k for k in self._query_cache if ctype in k]:
            del self._query_cache[key]

    # -- deferred structural changes -------------------------------------------------
    def queue_spawn(self, *components: Any, on_spawn: Callable[[Entity], None] | None = None) -> None:
        """Spawn at the next flush; ``on_spawn`` receives the new id."""

        def apply() -> None:
            e = self.spawn(*components)
            if on_spawn is not None:
                on_spawn(e)

        self._pending.append(apply)

    def queue_despawn(self, entity: Entity) -> None:
        """Despawn at the next flush."""
        self._pending.append(lambda: self.despawn(entity))

    def queue_add(self, entity: Entity, component: Any) -> None:
        """Attach a component at the next flush (skipped if the entity is gone by then)."""
        self._pending.append(lambda: self.add(entity, component) if self.alive(entity) else None)

    def queue_remove(self, entity: Entity, ctype: type) -> None:
        """Detach a component at the next flush."""
        self._pending.append(lambda: self.remove(entity, ctype))

    def flush(self) -> int:
        """Apply queued changes in the order they were queued; returns how many."""
        n = 0
        while self._pending:
            batch, self._pending = self._pending, []
            for change in batch:
                change()
                n += 1
        return n

    # -- resources --------------------------------------------------------------------
    def insert_resource(self, resource: Any) -> None:
        """Store a singleton keyed by its type (replacing one of that type)."""
        self._resources[type(resource)] = resource

    def resource(self, rtype: type[T]) -> T:
        """The resource of that type; ``KeyError`` says which plugin should have added it."""
        try:
            return self._resources[rtype]
        except KeyError:
            raise KeyError(f"no resource {rtype.__name__}: is its plugin installed?") from None

    def try_resource(self, rtype: type[T]) -> T | None:
        """The resource or ``None``."""
        return self._resources.get(rtype)

    def resources(self) -> Iterator[Any]:
        """All resources ordered by type name (stable for hashing)."""
        for t in sorted(self._resources, key=lambda t: (t.__module__, t.__qualname__)):
            yield self._resources[t]
