"""Every ragdoll's command and membership as columns: one row per ragdoll, in key order.

A crowd of a thousand animated puppets is driven every step, and most of the physics stage's
work was Python per puppet: one ``Command`` object each, its fields set one by one, then read
back one by one to find who must be in the model and to roll "the target it had last step" on.
Here each field is one array over all ragdolls (the rotations of all of them one flat ``[ΣJ, 4]``
array, ragdoll ``i``'s rows ``starts[i]:starts[i+1]``), so driving, the join test and the
roll-over are array operations, and only a ragdoll in an unusual state (held, simulated) costs
Python of its own.

A ragdoll that is added or removed changes the rows: the arrays are rebuilt at the next use
(:meth:`Commands.sync`), carrying every kept row, so a crowd spawned puppet by puppet is one rebuild.
"""

from __future__ import annotations

from typing import TypeVar

import numpy as np
from numpy.typing import NDArray

from engine.arrays import F64 as _F
from engine.arrays import I64

__all__ = ["Commands", "joint_rows"]

_BOOL = np.bool_
_T = TypeVar("_T", bound=np.generic)


def joint_rows(starts: I64, rows: I64) -> I64:
    """The flat joint rows of ragdolls ``rows``, in that order (``starts`` ``[N+1]``)."""
    counts = starts[rows + 1] - starts[rows]
    total = int(counts.sum())
    if total == 0:
        return np.zeros(0, dtype=np.int64)
    first = np.repeat(starts[rows] - np.concatenate([[0], np.cumsum(counts)[:-1]]), counts)
    return np.asarray(first + np.arange(total), dtype=np.int64)


class Commands:
    """The columns (see the module docstring). Per ragdoll ``i`` (``keys[i]`` ascending):

    - ``root [N,3]``, ``rot [ΣJ,4]``: the target pose (root position, local rotations);
    - ``muscle``, ``pin``, ``support [N]``: weights 0..1; ``kinematic [N]``: placed on the target;
    - ``hold [N]`` (the held joint's name or ``None``), ``hold_target [N,3]``;
    - ``last_root``, ``last_rot``, ``has_last``: the target it had last step (none after a placement);
    - ``prev_root``, ``prev_rot``, ``has_prev``: out of the model, the target before that;
    - ``in_model``, ``placed``, ``ghost [N]``, ``pool [N]`` (its pool slot or -1), ``reach [N]``.
    """

    def __init__(self) -> None:
        self.keys: I64 = np.zeros(0, dtype=np.int64)
        self.joints: I64 = np.zeros(0, dtype=np.int64)
        self.starts: I64 = np.zeros(1, dtype=np.int64)
        self.row: dict[int, int] = {}
        self.root: _F = np.zeros((0, 3))
        self.rot: _F = np.zeros((0, 4))
        self.muscle: _F = np.zeros(0)
        self.pin: _F = np.zeros(0)
        self.support: _F = np.zeros(0)
        self.kinematic: NDArray[np.bool_] = np.zeros(0, dtype=_BOOL)
        self.hold: list[str | None] = []
        self.hold_target: _F = np.zeros((0, 3))
        self.last_root: _F = np.zeros((0, 3))
        self.last_rot: _F = np.zeros((0, 4))
        self.has_last: NDArray[np.bool_] = np.zeros(0, dtype=_BOOL)
        self.prev_root: _F = np.zeros((0, 3))
        self.prev_rot: _F = np.zeros((0, 4))
        self.has_prev: NDArray[np.bool_] = np.zeros(0, dtype=_BOOL)
        self.in_model: NDArray[np.bool_] = np.zeros(0, dtype=_BOOL)
        self.placed: NDArray[np.bool_] = np.zeros(0, dtype=_BOOL)
        self.ghost: NDArray[np.bool_] = np.zeros(0, dtype=_BOOL)
        self.pool: I64 = np.zeros(0, dtype=np.int64)
        self.reach: _F = np.zeros(0)
        self._added: dict[int, tuple[_F, _F, float]] = {}
        self._removed: set[int] = set()

    # -- rows -----------------------------------------------------------------------------
    def add(self, key: int, root: _F, rot: _F, reach: float) -> None:
        """A new ragdoll at rest on ``root``, ``rot`` (a row from the next :meth:`sync`)."""
        self._removed.discard(key)
        self._added[key] = (root, rot, reach)

    def remove(self, key: int) -> None:
        """Drop a ragdoll's row (at the next :meth:`sync`)."""
        self._added.pop(key, None)
        self._removed.add(key)

    def sync(self) -> None:
        """Rebuild the rows after ragdolls were added or removed, carrying every kept row."""
        if not self._added and not self._removed:
            return
        keep = [k for k in self.keys.tolist() if k not in self._removed and k not in self._added]
        keys = np.array(sorted([*keep, *self._added]), dtype=np.int64)
        old_rows = np.array([self.row[k] for k in keep], dtype=np.int64)
        new_rows = np.searchsorted(keys, np.array(keep, dtype=np.int64))
        added = sorted(self._added)
        add_rows = np.searchsorted(keys, np.array(added, dtype=np.int64))
        joints = np.zeros(len(keys), dtype=np.int64)
        joints[new_rows] = self.joints[old_rows]
        joints[add_rows] = [len(self._added[k][1]) for k in added]
        starts = np.concatenate([[0], np.cumsum(joints)]).astype(np.int64)
        old_j, new_j = joint_rows(self.starts, old_rows), joint_rows(starts, new_rows)
        add_j = joint_rows(starts, add_rows)

        def per_row(old: NDArray[_T], fill: object) -> NDArray[_T]:
            out = np.empty((len(keys), *old.shape[1:]), dtype=old.dtype)
            out[new_rows] = old[old_rows]
            out[add_rows] = fill
            return out

        def per_joint(old: _F) -> _F:
            out = np.empty((int(starts[-1]), 4))
            out[new_j] = old[old_j]
            return out

        roots = np.array([self._added[k][0] for k in added]).reshape(-1, 3)
        rots = np.concatenate([self._added[k][1] for k in added]) if added else np.zeros((0, 4))
        self.root = per_row(self.root, roots)
        self.rot = per_joint(self.rot)
        self.rot[add_j] = rots
        self.muscle, self.pin, self.support = (per_row(a, 0.0) for a in (self.muscle, self.pin, self.support))
        self.kinematic = per_row(self.kinematic, False)
        hold: list[str | None] = [None] * len(keys)
        for r_old, r_new in zip(old_rows.tolist(), new_rows.tolist(), strict=True):
            hold[r_new] = self.hold[r_old]
        self.hold = hold
        self.hold_target = per_row(self.hold_target, 0.0)
        self.last_root, self.prev_root = per_row(self.last_root, 0.0), per_row(self.prev_root, 0.0)
        self.last_rot, self.prev_rot = per_joint(self.last_rot), per_joint(self.prev_rot)
        self.last_rot[add_j] = self.prev_rot[add_j] = 0.0
        self.has_last, self.has_prev = per_row(self.has_last, False), per_row(self.has_prev, False)
        self.in_model, self.placed, self.ghost = (per_row(a, False) for a in (self.in_model, self.placed, self.ghost))
        self.pool = per_row(self.pool, -1)
        self.reach = per_row(self.reach, np.array([self._added[k][2] for k in added]))
        self.keys, self.joints, self.starts = keys, joints, starts
        self.row = {k: i for i, k in enumerate(keys.tolist())}
        self._added.clear()
        self._removed.clear()

    def rows(self, keys: list[int]) -> I64:
        """The rows of ``keys`` (:meth:`sync` first); ``KeyError`` for a key without a ragdoll."""
        want = np.asarray(keys, dtype=np.int64)
        if self.whole(want):
            return np.arange(len(want), dtype=np.int64)
        idx = np.minimum(np.searchsorted(self.keys, want), max(len(self.keys) - 1, 0))
        missing = np.nonzero(self.keys[idx] != want)[0] if len(self.keys) else np.arange(len(want))
        if len(missing):
            raise KeyError(f"entity {int(want[missing[0]])} has no ragdoll in the physics world")
        return np.asarray(idx, dtype=np.int64)

    def whole(self, keys: I64 | list[int]) -> bool:
        """Whether ``keys`` are every ragdoll's, in row order."""
        return len(keys) == len(self.keys) and np.array_equal(self.keys, keys)

    def pose(self, i: int) -> tuple[_F, _F]:
        """Ragdoll ``i``'s target root and rotations (views)."""
        return self.root[i], self.rot[self.starts[i] : self.starts[i + 1]]

    def last(self, i: int) -> tuple[_F, _F] | None:
        """The target ragdoll ``i`` had last step (copies), ``None`` after a placement."""
        if not self.has_last[i]:
            return None
        return self.last_root[i].copy(), self.last_rot[self.starts[i] : self.starts[i + 1]].copy()

    def prev(self, i: int) -> tuple[_F, _F] | None:
        """Out of the model: the target before the last one (copies), if any."""
        if not self.has_prev[i]:
            return None
        return self.prev_root[i].copy(), self.prev_rot[self.starts[i] : self.starts[i + 1]].copy()

    def roll(self, rows: I64, *, keep_prev: bool) -> None:
        """The targets of ``rows`` (ascending) become their last targets (and, with ``keep_prev``,
        their last ones the ones before): a step has taken them."""
        if len(rows) == len(self.keys):  # the whole crowd (a walking one is all out of the model)
            if keep_prev:  # the buffers trade places: the last targets become the ones before
                self.prev_root, self.last_root = self.last_root, self.prev_root
                self.prev_rot, self.last_rot = self.last_rot, self.prev_rot
                self.has_prev, self.has_last = self.has_last, self.has_prev
            np.copyto(self.last_root, self.root)
            np.copyto(self.last_rot, self.rot)
            self.has_last[:] = True
            return
        j = joint_rows(self.starts, rows)
        if keep_prev:
            self.prev_root[rows] = self.last_root[rows]
            self.prev_rot[j] = self.last_rot[j]
            self.has_prev[rows] = self.has_last[rows]
        self.last_root[rows] = self.root[rows]
        self.last_rot[j] = self.rot[j]
        self.has_last[rows] = True
