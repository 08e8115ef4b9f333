"""Columns: a batch's array field stored as rows of one array the components view.

What must hold for the systems that use them: the components always show the values
written (in place, with no scatter), a read hands out the column itself with no gather, a
field that other code replaced is taken in (read) or overwritten (write) and its row
re-linked, and a batch that changes membership or shape is rebuilt from the fields.
Broken once to check the tests can fail: with ``_sync`` not copying a replaced value in
(``views[i][...] = value`` removed), ``test_a_replaced_field_is_taken_in_and_relinked``
fails (the column keeps the old row).
"""

from __future__ import annotations

import copy
from dataclasses import dataclass

import numpy as np
import pytest

from engine.columns import Column, Columns, Stacked, assignment_mark, columns, unassigned_since
from engine.ecs import World


@dataclass
class _Pose:
    root: np.ndarray


def _poses(n: int) -> list[_Pose]:
    return [_Pose(np.full(3, float(i))) for i in range(n)]


def test_write_makes_fields_views_and_read_is_the_column() -> None:
    poses = _poses(4)
    col = Column("root")
    values = np.arange(12.0).reshape(4, 3)
    col.write(poses, values)
    for i, p in enumerate(poses):
        assert np.array_equal(p.root, values[i])
    col.write(poses, values + 1.0)  # in place: the same view objects see the new rows
    assert all(np.array_equal(p.root, values[i] + 1.0) for i, p in enumerate(poses))
    column = col.read(poses)
    assert column is col.base
    column[2] = -5.0  # the column itself: a change in place reaches the component
    assert np.array_equal(poses[2].root, [-5.0, -5.0, -5.0])


def test_read_of_fresh_components_gathers_them() -> None:
    poses = _poses(3)
    col = Column("root")
    assert np.array_equal(col.read(poses), [[0.0] * 3, [1.0] * 3, [2.0] * 3])
    assert poses[1].root.base is col.base


def test_a_replaced_field_is_taken_in_and_relinked() -> None:
    poses = _poses(3)
    col = Column("root")
    col.read(poses)
    poses[1].root = np.array([7.0, 8.0, 9.0])  # other code replaces the field
    assert np.array_equal(col.read(poses)[1], [7.0, 8.0, 9.0])
    assert poses[1].root.base is col.base
    poses[0].root = np.array([1.0, 1.0, 1.0])
    col.write(poses, np.zeros((3, 3)))  # a write overwrites it and links the row again
    assert np.array_equal(poses[0].root, [0.0, 0.0, 0.0])
    assert poses[0].root.base is col.base


def test_part_of_the_batch_is_read_as_a_copy_and_written_in_its_rows() -> None:
    poses = _poses(4)
    col = Column("root")
    col.read(poses)
    part = [poses[3], poses[1]]
    rows = col.read(part)
    assert np.array_equal(rows, [[3.0] * 3, [1.0] * 3]) and rows.base is not col.base
    col.write(part, np.array([[30.0] * 3, [10.0] * 3]))
    assert [float(p.root[0]) for p in poses] == [0.0, 10.0, 2.0, 30.0]
    assert col.read(poses) is col.base  # the whole batch is still the column


def test_a_new_member_or_shape_rebuilds_the_column() -> None:
    poses = _poses(2)
    col = Column("root")
    first = col.read(poses)
    more = [*poses, _Pose(np.full(3, 5.0))]
    assert np.array_equal(col.read(more)[:, 0], [0.0, 1.0, 5.0]) and col.base is not first
    for p in more:
        p.root = np.zeros(4)  # fields of another shape
    assert col.read(more).shape == (3, 4)
    assert more[2].root.base is col.base


def test_ragged_fields_raise_and_scalars_are_refused() -> None:
    col = Column("root")
    with pytest.raises(ValueError):
        col.read([_Pose(np.zeros(3)), _Pose(np.zeros(2))])
    with pytest.raises(ValueError, match="array fields"):
        col.write(_poses(2), np.zeros(2))


def test_a_copied_batch_is_not_taken_for_the_column() -> None:
    poses = _poses(3)
    col = Column("root")
    col.write(poses, np.ones((3, 3)))
    poses2, col2 = copy.deepcopy((poses, col))  # a copied world: fields are copies, no views
    col2.write(poses2, np.full((3, 3), 4.0))
    assert all(np.array_equal(p.root, [4.0] * 3) for p in poses2)
    assert all(np.array_equal(p.root, [1.0] * 3) for p in poses)


def test_stacked_is_rebuilt_only_for_other_arrays() -> None:
    a, b = np.zeros((2, 3)), np.ones((2, 3))
    stack = Stacked()
    first = stack([a, b])
    assert stack([a, b]) is first
    c = np.full((2, 3), 2.0)
    assert np.array_equal(stack([a, c])[1], c)


def test_the_world_resource_is_made_once_and_never_hashed() -> None:
    world = World()
    cols = columns(world)
    assert columns(world) is cols and cols.get(_Pose, "root", 3) is cols.get(_Pose, "root", 3)
    assert cols.get(_Pose, "root", 3) is not cols.get(_Pose, "root", 4)
    assert Columns.SIM_STATE is False


def test_linked_is_the_column_only_while_it_is_exactly_the_owners_fields() -> None:
    """Broken once by letting :meth:`Column.linked` skip the check of replaced fields (the second
    assertion fails: a kernel would have written into a row no component shows)."""
    poses = tuple(_poses(3))
    col = Column("root")
    col.write(poses, np.ones((3, 3)))
    assert col.linked(poses) is col.base and col.linked(list(poses)) is col.base
    poses[1].root = np.zeros(3)  # other code replaced one field
    assert col.linked(poses) is None
    col.read(poses)  # taken in and linked again
    assert col.linked(poses) is col.base
    assert col.linked(poses[:2]) is None and col.linked(poses[::-1]) is None  # part, or another order


def test_a_tuple_of_owners_seen_whole_is_known_again_without_ids() -> None:
    """The tuple fast path of ``_rows`` must not outlive a rebuilt column (broken once by not
    clearing it in ``_link``: the old tuple was then taken for the new batch)."""
    poses = tuple(_poses(3))
    col = Column("root")
    col.write(poses, np.ones((3, 3)))
    assert col.linked(poses) is col.base  # seen whole: remembered
    others = _poses(2)
    col.write(others, np.zeros((2, 3)))  # another batch: the column is rebuilt
    assert col.linked(poses) is None
    assert np.array_equal(col.read(poses), np.ones((3, 3)))  # gathered from the fields again


def test_rows_are_where_part_of_the_batch_is_and_take_in_a_replaced_field() -> None:
    """:meth:`Column.rows`: the column itself and the owners' rows, a replaced field copied into its
    row first; ``None`` for an owner not in the column or a replaced field of another shape, and
    rows looked up anew after a relink. Broken once by returning the remembered rows without the
    per-call check (the replaced field was then not taken in: the row kept its old values)."""
    poses = _poses(5)
    col = Column("root")
    col.write(poses, np.arange(15.0).reshape(5, 3))
    part = (poses[3], poses[1])
    found = col.rows(part)
    assert found is not None and found[0] is col.base and found[1].tolist() == [3, 1]
    poses[1].root = np.full(3, -1.0)  # other code replaced a field: taken in, and the view is back
    found = col.rows(part)
    assert found is not None and found[1].tolist() == [3, 1]
    assert np.array_equal(found[0][1], [-1.0, -1.0, -1.0]) and poses[1].root.base is col.base
    assert col.rows((poses[0], _Pose(np.zeros(3)))) is None  # one of them is not in the column
    poses[3].root = np.zeros(4)
    assert col.rows(part) is None  # a replaced field of another shape
    col.write([*poses[::-1], _Pose(np.zeros(3))], np.zeros((6, 3)))  # relinked in another order: the rows follow
    found = col.rows(part)
    assert found is not None and found[1].tolist() == [1, 3]


@dataclass
class _Tracked:
    root: np.ndarray


@dataclass(slots=True)
class _Slotted:
    root: np.ndarray


def test_an_untouched_batch_is_known_intact_from_the_assignment_log_alone() -> None:
    """A column of a dataclass field reads the field's assignment log instead of comparing every row:
    a field changed behind the log's back (straight in ``__dict__``, which no code does) is therefore
    not seen, and one assigned is. Broken once by dropping the log (``_watched`` returning ``None``):
    the first ``linked`` then compares the rows and returns ``None``."""
    poses = tuple(_Tracked(np.full(3, float(i))) for i in range(4))
    col = Column("root")
    col.write(poses, np.zeros((4, 3)))
    poses[2].__dict__["root"] = np.ones(3)  # behind the log: not looked at
    assert col.linked(poses) is col.base
    poses[1].root = np.full(3, 5.0)  # assigned: in the log
    assert col.linked(poses) is None
    assert np.array_equal(col.read(poses)[1], [5.0, 5.0, 5.0]) and poses[1].root.base is col.base
    assert col.linked(poses) is col.base


def test_a_full_log_starts_an_epoch_and_the_column_compares_every_row_once() -> None:
    """Past the log's cap the log is cleared: a column that had not read it yet compares every row.
    Broken once by reading the cleared log from the old position (the replaced field was lost)."""
    from engine import columns as module

    poses = tuple(_Tracked(np.zeros(3)) for _ in range(3))
    col = Column("root")
    col.write(poses, np.zeros((3, 3)))
    poses[0].root = np.full(3, 2.0)
    other = _Tracked(np.zeros(3))
    for _ in range(module._LOG_CAP + 1):  # some other component assigned many times
        other.root = np.zeros(3)
    assert np.array_equal(col.read(poses)[0], [2.0, 2.0, 2.0]) and poses[0].root.base is col.base


@pytest.mark.parametrize("kind", ["slots", "mixed"])
def test_owners_without_a_log_are_compared_row_by_row(kind: str) -> None:
    """Slotted components (no ``__dict__``) or owners of several classes get no log: every call compares the rows."""
    first: object = _Slotted(np.zeros(3)) if kind == "slots" else _Tracked(np.zeros(3))
    poses = (first, _Slotted(np.zeros(3)), _Slotted(np.zeros(3)))
    col = Column("root")
    col.write(poses, np.zeros((3, 3)))
    assert col._watch is None
    poses[2].root = np.full(3, 4.0)
    assert col.linked(poses) is None
    assert np.array_equal(col.read(poses)[2], [4.0, 4.0, 4.0])
    assert col.linked(poses) is col.base


@dataclass
class _Tuned:
    gain: float = 1.0
    limit: float = 2.0


def test_a_mark_sees_any_assignment_since_even_across_a_cleared_log() -> None:
    """A mark (:func:`assignment_mark`) holds until one of its fields is assigned, whatever the value, and is not
    fooled by a log cleared at its cap and refilled to the length it had. Broken once by comparing the logs' lengths
    instead of their counts: the last assertion then fails."""
    from engine import columns as module

    tuned = _Tuned()
    mark = assignment_mark(_Tuned, ("gain", "limit"))
    assert unassigned_since(mark)
    tuned.limit = 2.0  # the same value, still an assignment
    assert not unassigned_since(mark)
    tuned.gain = 3.0
    mark = assignment_mark(_Tuned, ("gain", "limit"))
    assert unassigned_since(mark) and not unassigned_since(None)
    log = module._field_log(_Tuned, "gain")
    assert log is not None
    length = len(log.log)
    for _ in range(module._LOG_CAP):  # the log cleared at its cap and refilled to the length it had
        tuned.gain = 3.0
    assert len(log.log) == length
    assert not unassigned_since(mark)
