"""Row fields: a linked component reads, writes and hashes exactly as a plain one.

Shown to fail when broken: ``_RowField.__get__`` returning ``block.arrays[name][row]`` (an
``np.float64``) instead of ``.item(row)`` fails the hash and type tests; ``_state_columns`` (the
state hash's read of a block) gathering a number column with ``list`` (``np.float64`` values) instead
of ``tolist`` fails the hash test; ``_store`` accepting an
``np.float64`` (no unlink) fails ``test_a_value_the_block_cannot_hold_unlinks_the_component``.
"""

from __future__ import annotations

import copy
import math
import pickle
from dataclasses import dataclass, field

import numpy as np
import pytest

from engine.ecs import World
from engine.hashing import state_hash
from engine.rows import RowStore, keep_in_rows, row_store


@dataclass
class Body:
    heading: float = 0.0
    held_by: int | None = None
    velocity: np.ndarray = field(default_factory=lambda: np.zeros(3))
    last: np.ndarray | None = None
    tag: object = None
    plain: float = 0.0


keep_in_rows(
    Body,
    heading=("float", (), False),
    held_by=("int", (), True),
    velocity=("vector", (3,), False),
    last=("vector", (3,), True),
    tag=("object", (), False),
)


def _random_bodies(rng: np.random.Generator, n: int) -> list[Body]:
    specials = [0.0, -0.0, math.inf, -math.inf, math.nan, 5e-324, 1e308]
    out = []
    for i in range(n):
        h = float(rng.choice(specials)) if rng.random() < 0.3 else float(rng.normal())
        out.append(
            Body(
                heading=h,
                held_by=None if rng.random() < 0.5 else int(rng.integers(0, 2**40)),
                velocity=rng.normal(size=3),
                last=None if rng.random() < 0.3 else rng.normal(size=3),
                tag=("t", i),
                plain=float(i),
            )
        )
    return out


def _world(bodies: list[Body]) -> World:
    w = World()
    for b in bodies:
        w.spawn(b)
    return w


@pytest.mark.parametrize("seed", range(5))
def test_a_linked_batch_hashes_and_reads_exactly_as_plain_objects(seed: int) -> None:
    rng = np.random.default_rng(seed)
    plain = _random_bodies(np.random.default_rng(seed), 40)
    linked = _random_bodies(np.random.default_rng(seed), 40)
    wp, wl = _world(plain), _world(linked)
    owners = tuple(linked)
    block = RowStore().block(Body, owners)
    assert not block.stale and "_row_link" in linked[0].__dict__
    assert state_hash(wp) == state_hash(wl)
    for p, q in zip(plain, linked, strict=True):
        assert type(q.heading) is float and np.array_equal(p.heading, q.heading, equal_nan=True)
        assert math.copysign(1.0, p.heading) == math.copysign(1.0, q.heading)
        assert type(q.held_by) is type(p.held_by) and q.held_by == p.held_by
        assert (q.last is None) == (p.last is None) and q.tag == p.tag
    # Writes through the objects and through the arrays are both seen by the other side.
    for _ in range(30):
        i = int(rng.integers(len(plain)))
        value = float(rng.choice([rng.normal(), -0.0, math.nan]))
        plain[i].heading = linked[i].heading = value
        if rng.random() < 0.5:
            plain[i].held_by = linked[i].held_by = None
        v = rng.normal(size=3)
        plain[i].velocity = v.copy()
        linked[i].velocity = v.copy()
        plain[i].last = linked[i].last = None if rng.random() < 0.3 else rng.normal(size=3)
    block.arrays["heading"][:5] = -0.0
    for b in plain[:5]:
        b.heading = -0.0
    assert not block.stale and state_hash(wp) == state_hash(wl)
    # One component unlinked: the hash reads the others from the block and it as a plain object.
    plain[3].heading = linked[3].heading = np.float64(0.25)  # type: ignore[assignment]  # unlinks: on purpose
    assert block.stale and state_hash(wp) == state_hash(wl)


def test_a_value_the_block_cannot_hold_unlinks_the_component() -> None:
    bodies = _random_bodies(np.random.default_rng(1), 6)
    store = RowStore()
    owners = tuple(bodies)
    block = store.block(Body, owners)
    kept_velocity = bodies[3].velocity
    bodies[2].heading = np.float64(1.5)  # type: ignore[assignment]  # the wrong type on purpose
    assert type(bodies[2].heading) is np.float64 and "_row_link" not in bodies[2].__dict__
    assert block.stale and "_row_link" in bodies[3].__dict__  # the others stay linked meanwhile
    assert np.array_equal(bodies[3].velocity, kept_velocity)
    unlinked = bodies[2].velocity  # an unlinked component's arrays are its own, writable, apart from the block
    unlinked[0] = 42.0
    assert bodies[2].velocity[0] == 42.0 and not np.any(block.arrays["velocity"] == 42.0)
    again = store.block(Body, owners)  # cannot link a np.float64 exactly: stays plain, not retried
    assert again.stale and again.failed and store.block(Body, owners) is again
    assert type(bodies[2].heading) is np.float64
    bodies[2].heading = 1.5
    store.block(Body, owners)  # same tuple, failed: not retried
    fresh = store.block(Body, tuple(bodies))
    assert not fresh.stale and type(bodies[2].heading) is float
    bodies[0].velocity = np.zeros(4)  # another shape
    assert bodies[0].velocity.shape == (4,) and fresh.stale
    bodies[1].held_by = 7.0  # type: ignore[assignment]  # a float in an int field
    assert type(bodies[1].held_by) is float


def test_an_array_read_keeps_its_values_as_a_plain_fields_array_does() -> None:
    """``old = c.velocity; c.velocity = new; c.velocity = old`` restores the old values, and an array read
    before an assignment or a system's whole-array write keeps the values it was read with — as a plain
    field's array does (the state-hash test saves and restores every field this way). Shown to fail when a
    read hands out the row's view (``_frozen`` returning ``row``): the restore leaves ``new`` in place."""
    rng = np.random.default_rng(4)
    plain = _random_bodies(np.random.default_rng(4), 5)
    linked = _random_bodies(np.random.default_rng(4), 5)
    block = RowStore().block(Body, tuple(linked))
    for p, q in zip(plain, linked, strict=True):
        for name in ("velocity", "last"):
            held = (getattr(p, name), getattr(q, name))
            new = rng.normal(size=3)
            setattr(p, name, new.copy())
            setattr(q, name, new.copy())
            assert held[1] is None or not np.array_equal(held[1], new)  # the earlier read did not follow
            setattr(p, name, held[0])
            setattr(q, name, held[1])
            for a, b in ((getattr(p, name), getattr(q, name)), held):
                assert (a is None and b is None) or np.array_equal(a, b)
    before = [q.velocity for q in linked]
    block.arrays["velocity"][:] = 7.0  # a system stepping the crowd writes the rows in place
    assert all(np.array_equal(v, p.velocity) for v, p in zip(before, plain, strict=True))
    assert all(np.all(q.velocity == 7.0) for q in linked) and not block.stale


def test_changing_a_read_array_in_place_raises_instead_of_being_lost() -> None:
    """On a plain field ``c.velocity[0] = x`` changes the field; a linked read is a copy, so the change would be
    lost without a word: it raises, and the row keeps its value. Shown to fail when the copy is left writable."""
    bodies = _random_bodies(np.random.default_rng(5), 3)
    RowStore().block(Body, tuple(bodies))
    kept = bodies[1].velocity.copy()
    with pytest.raises(ValueError, match="read-only"):
        bodies[1].velocity[0] = 99.0
    last = bodies[0].last if bodies[0].last is not None else bodies[2].last
    assert last is not None
    with pytest.raises(ValueError, match="read-only"):
        last += 1.0
    assert np.array_equal(bodies[1].velocity, kept)


@pytest.mark.parametrize("how", ["copy", "deepcopy", "pickle"])
def test_copies_of_a_linked_component_are_plain_objects_of_its_values(how: str) -> None:
    """``copy``, ``deepcopy`` and ``pickle`` take a linked component as the plain object it stands for: no link,
    its own writable arrays, not the block (a pickle carrying the block would hold every row). Shown to fail
    without ``__getstate__`` (``_plain_state``): the copy keeps ``_row_link``."""
    bodies = _random_bodies(np.random.default_rng(6), 50)
    RowStore().block(Body, tuple(bodies))
    original = bodies[1]
    twin = {"copy": copy.copy, "deepcopy": copy.deepcopy, "pickle": lambda b: pickle.loads(pickle.dumps(b))}[how](
        original
    )
    assert "_row_link" not in twin.__dict__ and "_row_link" in original.__dict__
    assert twin.heading == original.heading and twin.held_by == original.held_by and twin.tag == original.tag
    assert np.array_equal(twin.velocity, original.velocity)
    twin.velocity[0] = 99.0
    twin.heading = 4.0
    assert original.velocity[0] != 99.0 and original.heading != 4.0
    if how == "pickle":
        assert len(pickle.dumps(original)) < 1000  # one body, not the block of fifty


def test_copy_of_a_linked_component_is_plain_and_does_not_share_its_row() -> None:
    bodies = _random_bodies(np.random.default_rng(2), 3)
    RowStore().block(Body, tuple(bodies))
    twin = copy.copy(bodies[1])
    assert "_row_link" not in twin.__dict__ and twin.heading == bodies[1].heading
    twin.velocity[0] = 99.0
    twin.heading = 4.0
    assert bodies[1].velocity[0] != 99.0 and bodies[1].heading != 4.0


def test_rows_maps_a_sub_batch_and_forgets_it_with_the_block() -> None:
    bodies = _random_bodies(np.random.default_rng(3), 8)
    w = World()
    store = row_store(w)
    assert w.resource(RowStore) is store
    whole = tuple(bodies)
    block = store.block(Body, whole)
    some = (bodies[5], bodies[1], bodies[6])
    found = store.rows(Body, some)
    assert found is not None and found[0] is block and found[1].tolist() == [5, 1, 6]
    assert store.rows(Body, whole) == (block, slice(None))
    assert store.rows(Body, (Body(),)) is None  # not in the block
    store.block(Body, tuple(reversed(bodies)))  # linked anew: the old rows are gone
    found = store.rows(Body, some)
    assert found is not None and found[1].tolist() == [2, 6, 1]


def test_an_unknown_kind_is_refused() -> None:
    with pytest.raises(ValueError, match="unknown row kind"):
        keep_in_rows(Body, plain=("complex", (), False))
