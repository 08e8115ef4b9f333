"""The animation stage's batches: each locomotion set's puppets and their components, kept between steps.

:func:`engine.blend.locomotion.animate` poses the puppets of one locomotion set together.
Gathering their components puppet by puppet every step (entities, transforms, players,
local poses, leg-IK requests) is Python work per puppet for nothing: between structural
changes they are the same objects. A :class:`Group` keeps them as tuples, built from the
world's kept batch (:func:`engine.batches.batch`, rebuilt on every structural change) and
from the players' set names (read every step in one C-level pass, since any code may
change a ``library_key``). Tuples, because a column (:mod:`engine.columns`) recognises the
very same tuple of owners without comparing ids, so every column of the stage is found
whole at no cost per puppet.

The one field kept here that is no component is each IK request's ``foot_lock``: plain code
may replace it, so :meth:`Group.foot_locks` checks it before handing it out: a C-level pass,
and none while no request's ``foot_lock`` was assigned since the last (:func:`engine.columns.assignment_mark`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from operator import attrgetter, is_
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from engine.batches import Batch
from engine.columns import Mark, assignment_mark, unassigned_since
from engine.components import LocalPose, Transform
from engine.ecs import Entity
from engine.ik.foot_lock import FootLock
from engine.ik.system import IKRequest
from engine.rows import RowBlock

if TYPE_CHECKING:
    from engine.blend.locomotion import LocomotionPlayer

__all__ = ["Group", "Groups"]

_KEY = attrgetter("library_key")
_FOOT_LOCK = attrgetter("foot_lock")


@dataclass
class Group:
    """One locomotion set's puppets in entity order, and their components.

    Attributes:
        key: the set's name.
        entities: the puppets.
        transforms: their transforms.
        players: their locomotion players.
        poses: their local poses, ``None`` while some puppet has none yet (its first step).
        ik: the leg-IK requests of the puppets that have one.
        ik_rows: which rows those are, ``None`` when every puppet has one.
        locks: their foot locks as last handed out (see :meth:`foot_locks`).
        locks_mark: where the requests' ``foot_lock`` assignment log stood when ``locks`` was checked.
        settled: the settle flags last written to ``locks`` by the animation stage, and where the foot locks'
            ``settle`` assignment log stood after (see :func:`engine.blend.locomotion._contacts`).
        scaled: the players' scales as last read, and where the players' ``scale`` assignment log stood then.
    """

    key: str
    entities: list[Entity]
    transforms: tuple[Transform, ...]
    players: tuple[LocomotionPlayer, ...]
    poses: tuple[LocalPose, ...] | None
    ik: tuple[IKRequest, ...]
    ik_rows: NDArray[np.intp] | None
    locks: tuple[FootLock, ...]
    locks_mark: Mark | None = None
    settled: tuple[tuple[FootLock, ...], NDArray[np.bool_], Mark | None] | None = field(default=None, repr=False)
    scaled: tuple[NDArray[np.float64], Mark | None] | None = field(default=None, repr=False)

    def foot_locks(self) -> tuple[FootLock, ...]:
        """The IK requests' foot locks (the same tuple as last time unless one was replaced)."""
        if unassigned_since(self.locks_mark):
            return self.locks
        if not all(map(is_, map(_FOOT_LOCK, self.ik), self.locks)):
            self.locks = tuple(map(_FOOT_LOCK, self.ik))
        self.locks_mark = assignment_mark(IKRequest, ("foot_lock",))
        return self.locks


class Groups:
    """The groups of the last batch seen, and the set names they were split by."""

    def __init__(self) -> None:
        self._batch: Batch | None = None
        self._keys: list[str] = []
        self._groups: list[Group] = []

    def of(self, kept: Batch, block: RowBlock | None = None) -> list[Group]:
        """The groups of ``kept`` (rows ``(Transform, Puppet, LocomotionPlayer)``, optional
        ``(LocalPose, IKRequest)``), in order of each set's first puppet; the set names are read from
        ``block`` when the players are linked to it (:mod:`engine.rows`), whole."""
        keys = list(map(_KEY, kept.lists[2])) if block is None else block.arrays["library_key"].tolist()
        if kept is self._batch and keys == self._keys:
            return self._groups
        rows: dict[str, list[int]] = {}
        for i, key in enumerate(keys):
            rows.setdefault(key, []).append(i)
        self._batch, self._keys = kept, keys
        self._groups = [_group(kept, key, index) for key, index in rows.items()]
        return self._groups


def _group(kept: Batch, key: str, index: list[int]) -> Group:
    """The group of rows ``index`` of ``kept``."""
    transforms, _, players, poses, requests = kept.lists
    pick = [transforms, players, poses, requests]
    if len(index) != len(kept.entities):
        pick = [tuple(column[i] for i in index) for column in pick]
    mine_transforms, mine_players, mine_poses, mine_requests = pick
    has = [r is not None for r in mine_requests]
    ik = tuple(r for r in mine_requests if r is not None)
    return Group(
        key=key,
        entities=[kept.entities[i] for i in index],
        transforms=tuple(mine_transforms),
        players=tuple(mine_players),
        poses=None if any(p is None for p in mine_poses) else tuple(mine_poses),
        ik=ik,
        ik_rows=None if all(has) else np.flatnonzero(has),
        locks=tuple(map(_FOOT_LOCK, ik)),
    )
