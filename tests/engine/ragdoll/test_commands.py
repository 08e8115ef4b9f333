"""The ragdolls' command columns: rows survive adds and removes, and a step's roll-over keeps
"the target it had last step" (and, out of the model, the one before) for each ragdoll."""

from __future__ import annotations

import numpy as np
import pytest

from engine import quat
from engine.ragdoll._commands import Commands, joint_rows


def _rot(n: int, angle: float) -> np.ndarray:
    return quat.from_axis_angle(np.tile([0.0, 1.0, 0.0], (n, 1)), np.full(n, angle))


def _store() -> Commands:
    c = Commands()
    for key, joints in ((7, 3), (2, 2), (5, 4)):
        c.add(key, np.array([float(key), 0.0, 0.0]), _rot(joints, 0.1 * key), 1.0 + key)
    c.sync()
    return c


def test_rows_follow_key_order_and_carry_over_adds_and_removes() -> None:
    c = _store()
    assert c.keys.tolist() == [2, 5, 7]
    assert c.starts.tolist() == [0, 2, 6, 9]
    c.muscle[c.row[5]] = 0.5
    c.hold[c.row[7]] = "chest"
    c.remove(2)
    c.add(3, np.array([3.0, 1.0, 0.0]), _rot(1, 0.3), 9.0)
    c.sync()
    assert c.keys.tolist() == [3, 5, 7]
    assert c.joints.tolist() == [1, 4, 3]
    assert c.muscle.tolist() == [0.0, 0.5, 0.0]
    assert c.hold == [None, None, "chest"]
    assert c.reach.tolist() == [9.0, 6.0, 8.0]
    root, rot = c.pose(c.row[7])
    assert root.tolist() == [7.0, 0.0, 0.0]
    np.testing.assert_array_equal(rot, _rot(3, 0.1 * 7))
    assert c.pool.tolist() == [-1, -1, -1] and not c.in_model.any()


def test_rows_of_unknown_key_is_a_key_error() -> None:
    c = _store()
    assert c.rows([7, 2]).tolist() == [2, 0]
    with pytest.raises(KeyError, match="entity 4"):
        c.rows([5, 4])


def test_roll_keeps_the_last_target_and_the_one_before() -> None:
    """Broken once by not trading the buffers in the whole-crowd path (prev stayed empty): it failed."""
    for rows in (np.array([0, 1, 2]), np.array([1])):  # the whole crowd, and one ragdoll
        c = _store()
        first = c.rot.copy()
        c.roll(rows, keep_prev=True)
        assert c.has_last[rows].all() and not c.has_prev.any()
        c.rot[:] = _rot(len(c.rot), 1.0)
        c.root[:] += 1.0
        c.roll(rows, keep_prev=True)
        j = joint_rows(c.starts, rows)
        assert c.has_prev[rows].all()
        np.testing.assert_array_equal(c.prev_rot[j], first[j])
        np.testing.assert_array_equal(c.last_rot[j], c.rot[j])
        np.testing.assert_array_equal(c.last_root[rows] - 1.0, c.prev_root[rows])
        i = int(rows[0])
        last, prev = c.last(i), c.prev(i)
        assert last is not None and prev is not None
        np.testing.assert_array_equal(last[1], c.pose(i)[1])
