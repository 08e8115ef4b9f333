"""Kept batches: the component lists of a query, the same objects until a structural change.

Shown to fail when broken: a batch kept across a despawn or a replaced component (``Batches.get``
returning the kept one without comparing the queries) fails the second and third tests."""

from dataclasses import dataclass

from engine.batches import batch
from engine.ecs import World


@dataclass
class A:
    v: int = 0


@dataclass
class B:
    v: int = 0


def _world() -> tuple[World, list[int]]:
    w = World()
    return w, [w.spawn(A(i), B(i)) if i % 2 else w.spawn(A(i)) for i in range(5)]


def test_a_batch_lists_the_components_and_is_kept_while_nothing_changes() -> None:
    w, es = _world()
    first = batch(w, "k", (A,), (B,))
    assert first.entities == es
    assert [a.v for a in first.lists[0]] == [0, 1, 2, 3, 4]
    assert [b.v if b is not None else None for b in first.lists[1]] == [None, 1, None, 3, None]
    assert first.missing == (False, True)
    w.get(es[0], A).v = 7  # values are read fresh by the caller: no rebuild needed
    assert batch(w, "k", (A,), (B,)) is first


def test_a_batch_is_rebuilt_after_a_spawn_or_despawn() -> None:
    w, es = _world()
    first = batch(w, "k", (A,), (B,))
    w.despawn(es[1])
    second = batch(w, "k", (A,), (B,))
    assert second is not first and second.entities == [es[0], *es[2:]]
    e = w.spawn(A(9), B(9))
    third = batch(w, "k", (A,), (B,))
    assert third.entities[-1] == e and third.lists[1][-1] is w.get(e, B)


def test_a_batch_is_rebuilt_when_an_optional_component_is_replaced_added_or_removed() -> None:
    w, es = _world()
    batch(w, "k", (A,), (B,))
    new = B(42)
    w.add(es[1], new)  # replaced
    assert batch(w, "k", (A,), (B,)).lists[1][1] is new
    w.add(es[0], B(5))  # added
    assert batch(w, "k", (A,), (B,)).lists[1][0].v == 5
    w.remove(es[3], B)
    kept = batch(w, "k", (A,), (B,))
    assert kept.lists[1][3] is None and kept.missing == (False, True)


def test_batches_of_different_keys_are_apart() -> None:
    w, es = _world()
    assert batch(w, "only a", (A,)).lists == (tuple(w.get(e, A) for e in es),)
    assert batch(w, "a and b", (A, B)).entities == [es[1], es[3]]
