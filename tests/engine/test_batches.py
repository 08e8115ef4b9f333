"""Kept batches: the component lists of a query, the same objects until a structural change.

Shown to fail when broken: a batch kept across a despawn or a replaced component (``Batches.get``
returning the kept one without comparing the queries) fails the second and third tests."""

from dataclasses import dataclass

import pytest

from engine.batches import assign, batch
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


def test_a_kept_batch_asks_no_query_while_the_world_has_no_structural_change() -> None:
    """Broken once by dropping the structure-count shortcut of ``Batches.get`` (the queries were asked again)."""
    w, es = _world()
    first = batch(w, "k", (A,), (B,))
    asked: list[tuple[type, ...]] = []
    query = w.query
    w.query = lambda *types: asked.append(types) or query(*types)  # type: ignore[method-assign]  # a spy
    w.get(es[0], A).v = 3  # a value, not the structure
    assert batch(w, "k", (A,), (B,)) is first and asked == []
    assert batch(w, "k", (A,)) is not first  # the same key asked for other types: built anew
    w.add(es[0], B(1))
    assert batch(w, "k", (A,), (B,)).lists[1][0] is w.get(es[0], B) and asked


def test_the_structure_count_moves_on_every_structural_change_only() -> None:
    w, es = _world()
    seen = [w.structure]
    w.get(es[0], A).v = 8
    w.query(A)
    seen.append(w.structure)
    assert seen[-1] == seen[-2]
    for change in (
        lambda: w.spawn(A()),
        lambda: w.despawn(es[0]),
        lambda: w.add(es[1], A(2)),
        lambda: w.remove(es[1], B),
    ):
        change()
        seen.append(w.structure)
        assert seen[-1] > seen[-2]


def test_assign_sets_every_row_in_order_and_refuses_a_short_list() -> None:
    """Broken once by assigning ``values`` reversed: the first assertion fails."""
    objects = [A(i) for i in range(4)]
    assign(objects, "v", [10, 11, 12, 13])
    assert [a.v for a in objects] == [10, 11, 12, 13]
    with pytest.raises(ValueError, match="3 values of v for 4 objects"):
        assign(objects, "v", [1, 2, 3])
