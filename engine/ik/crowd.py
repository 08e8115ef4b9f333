"""The IK stage's crowd pass: a crowd's feet planted in two compiled calls, no Python per puppet.

:func:`~engine.ik.grounding.ground_feet_batch` already grounds a crowd of one skeleton on
compiled kernels, but around them the stage did Python per puppet every step: grouping the
requests, stacking offsets, fitting and grouping the foot locks, reading their state from
the components, writing the pelvis shifts back. That cost several times the kernels. Here
a :class:`CrowdPlan` is made once per membership: the puppets that only ask to have their
feet planted (no effectors, no hands), share one skeleton and have live foot locks of one
tuning. Each step it checks, with a handful of C-level passes over the members
(``map``/``all``, no Python frame per puppet), that nothing about them changed, then runs
:func:`~engine.ik._ground_kernel.legs_fk`, the ground query, and
:func:`~engine.ik._ground_kernel.ground_crowd` on the columns themselves
(:meth:`engine.columns.Column.linked`): the local poses and the foot locks' state are
updated in place.

The arithmetic is the compiled path's of :func:`~engine.ik.grounding.ground_feet_batch`
operation for operation (the same kernel helpers), so states hash the same. Whatever the
plan cannot vouch for (a lock replaced, one puppet jumping, a field assigned by other
code, numba off) is left to the general path of :func:`engine.ik.system.ik_system`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from itertools import repeat
from operator import attrgetter, is_
from typing import Any

import numpy as np

from engine import jit
from engine.arrays import F64 as F
from engine.arrays import I64
from engine.columns import Columns
from engine.components import LocalPose, Puppet
from engine.ik import _ground_kernel as _kernel
from engine.ik.foot_lock import FootLock
from engine.ik.grounding import (
    _LOCK_STATE,
    _LOCK_TYPES,
    ALIGN_HEIGHT,
    CONTACT_HEIGHT,
    HUMANOID_LEGS,
    MAX_PELVIS_SHIFT,
    GroundQuery,
    PlaneGround,
)
from engine.skeleton import Skeleton

__all__ = ["CrowdPlan", "current_plan", "ground_crowd", "plan_crowd"]

_GROUNDING = attrgetter("grounding")
_EFFECTORS = attrgetter("effectors")
_SPHERE = attrgetter("sphere_centre")
_WEIGHT = attrgetter("grounding_weight")
_LOCK = attrgetter("foot_lock")
_SKELETON = attrgetter("skeleton")
_OFFSETS = attrgetter("offsets")
_ENABLED = attrgetter("enabled")
_SETTLE = attrgetter("settle")
_SETTINGS = attrgetter(
    "release_time",
    "max_stretch",
    "release_height",
    "settle_gap",
    "max_twist",
    "settle_twist",
    "step_time",
    "step_height",
)


def _plain(req: Any, settings: tuple[float, ...]) -> bool:
    """A request the crowd pass serves: no hands on a sphere, a live lock of tuning ``settings``."""
    lock = req.foot_lock
    return (
        req.sphere_centre is None
        and lock is not None
        and lock.enabled
        and lock.contacts is not None
        and lock.settings() == settings
    )


def _same_objects(a: Sequence[Any], b: Sequence[Any]) -> bool:
    """``a[i] is b[i]`` for every ``i`` (equal lengths), in C."""
    return len(a) == len(b) and all(map(is_, a, b))


@dataclass
class CrowdPlan:
    """Who the crowd pass serves, and what it checks every step that they still are.

    Attributes:
        table: the world's query result the plan was made for (the ECS hands out the same
            list until an entity or component of the query changes; kept so its id is not reused).
        all_requests, grounding: every row's request and its ``grounding`` flag then (a puppet
            that jumps changes the plan).
        rows: the members' positions in ``table`` (none: no crowd, everyone takes the general path).
        skeleton, puppets: their shared skeleton and their ``Puppet`` components; ``skeletons``/``offset_fields`` each member's own
            ``Puppet.skeleton``/``Puppet.offsets`` objects, and ``offsets`` their stack ``[P, J, 3]``.
        locals_, requests, locks: the members' components, in row order (tuples: the columns
            know an unchanged tuple of owners without comparing ids).
        settings, settings_array: the locks' tuning (:meth:`FootLock.settings`), one for all.
    """

    table: list[tuple[Any, ...]]
    all_requests: list[Any]
    grounding: list[bool]
    rows: list[int]
    skeleton: Skeleton | None
    puppets: list[Puppet]
    skeletons: list[Skeleton]
    offset_fields: list[Any]
    offsets: F
    locals_: tuple[LocalPose, ...]
    requests: list[Any]
    locks: tuple[FootLock, ...]
    settings: tuple[float, ...]
    settings_array: F
    legs: I64
    soles: F
    tips: F
    heels: F
    knees: F


def plan_crowd(table: list[tuple[Any, ...]], same_as: Any, batch_from: int) -> CrowdPlan:
    """The crowd of ``table`` (rows ``(entity, Puppet, LocalPose, IKRequest)``).

    It is the largest of the groups that :func:`engine.ik.system.ik_system` grounds as one
    batch (rows that ask for grounding and no effectors, of one skeleton — ``same_as`` maps a
    skeleton to its canonical equal — at least ``batch_from`` of them), taken whole or not at
    all, and only if every member is plain: no hands on a sphere, a live foot lock, one lock
    tuning. Otherwise the plan has no members and only remembers that there is no crowd."""
    requests = [row[3] for row in table]
    groups: dict[int, list[int]] = {}
    for i, (_, puppet, _, req) in enumerate(table):
        if req.grounding and not req.effectors:
            groups.setdefault(id(same_as(puppet.skeleton)), []).append(i)
    rows = max(groups.values(), key=len) if groups else []
    settings = table[rows[0]][3].foot_lock.settings() if rows else ()
    if len(rows) < batch_from or not all(_plain(table[i][3], settings) for i in rows):
        rows = []
    puppets: list[Puppet] = [table[i][1] for i in rows]
    members = [table[i][3] for i in rows]
    locks = tuple(req.foot_lock for req in members)
    sk = same_as(puppets[0].skeleton) if puppets else None
    legs = HUMANOID_LEGS
    idx = np.array(
        [(sk.index(leg.upper), sk.index(leg.lower), sk.index(leg.foot)) for leg in legs] if sk else [],
        dtype=np.int64,
    ).reshape(-1, 3)
    return CrowdPlan(
        table=table,
        all_requests=requests,
        grounding=list(map(_GROUNDING, requests)),
        rows=rows,
        skeleton=sk,
        puppets=puppets,
        skeletons=list(map(_SKELETON, puppets)),
        offset_fields=list(map(_OFFSETS, puppets)),
        offsets=np.array([p.joint_offsets() for p in puppets], dtype=np.float64),
        locals_=tuple(table[i][2] for i in rows),
        requests=members,
        locks=locks,
        settings=settings,
        settings_array=np.array(settings, dtype=np.float64),
        legs=idx,
        soles=np.array([leg.sole for leg in legs], dtype=np.float64),
        tips=np.array([sk.tips[f] for _, _, f in idx] if sk else np.zeros((0, 3)), dtype=np.float64),
        heels=np.array([leg.heel for leg in legs], dtype=np.float64),
        knees=np.array([leg.knee_forward for leg in legs], dtype=np.float64),
    )


def _holds(plan: CrowdPlan, table: list[tuple[Any, ...]]) -> bool:
    """Whether ``plan`` still describes ``table``'s crowd this step (C-level passes over the rows).

    A puppet outside the crowd that becomes fit to join it without its ``grounding`` flag
    changing (its effectors cleared, say) is noticed at the next change of membership; until
    then it is served, correctly, by the general path."""
    if table is not plan.table or list(map(_GROUNDING, plan.all_requests)) != plan.grounding:
        return False
    if not plan.rows:
        return True
    reqs, locks = plan.requests, plan.locks
    return (
        not any(map(_EFFECTORS, reqs))
        and all(map(is_, map(_SPHERE, reqs), repeat(None)))
        and _same_objects(list(map(_LOCK, reqs)), locks)
        and all(map(_ENABLED, locks))
        and _same_objects(list(map(_SKELETON, plan.puppets)), plan.skeletons)
        and _same_objects(list(map(_OFFSETS, plan.puppets)), plan.offset_fields)
        and list(map(_SETTINGS, locks)).count(plan.settings) == len(locks)
    )


def current_plan(plan: CrowdPlan | None, table: list[tuple[Any, ...]], same_as: Any, batch_from: int) -> CrowdPlan:
    """``plan`` if it still holds for ``table``, else a new one (:func:`plan_crowd`)."""
    if plan is not None and _holds(plan, table):
        return plan
    return plan_crowd(table, same_as, batch_from)


def ground_crowd(plan: CrowdPlan, cols: Columns, ground: GroundQuery, dt: float) -> bool:
    """Plant the feet of ``plan``'s crowd (a plan that holds this step: :func:`current_plan`) in place,
    if numba runs and every member's pose and lock state are in their columns
    (:meth:`~engine.columns.Column.linked`); ``False`` (nothing done) otherwise. Writes each
    member's ``pelvis_shift``."""
    sk, reqs, locks = plan.skeleton, plan.requests, plan.locks
    if sk is None or not jit.enabled():
        return False
    joints, legs = sk.num_joints, len(plan.legs)
    roots = cols.get(LocalPose, "root", joints).linked(plan.locals_)
    rots = cols.get(LocalPose, "rotations", joints).linked(plan.locals_)
    contacts = cols.get(FootLock, "contacts", legs).linked(locks)
    points, weights, planted, stepping, yaw, animated = (
        cols.get(FootLock, name, legs, _LOCK_TYPES.get(name, np.float64)).linked(locks) for name in _LOCK_STATE
    )
    if roots is None or rots is None or contacts is None:
        return False
    if points is None or weights is None or planted is None or stepping is None or yaw is None or animated is None:
        return False
    count = len(reqs)
    weight = np.fromiter(map(_WEIGHT, reqs), dtype=np.float64, count=count)
    if np.any((weight < 0.0) | (weight > 1.0)):
        raise ValueError("weight must lie in 0..1")
    settle = np.fromiter(map(_SETTLE, locks), dtype=np.bool_, count=count)
    ankles, hips, sole, qfeet = (np.empty((count, legs, 3)), np.empty((count, legs, 3)),
                                 np.empty((count, legs, 3)), np.empty((count, legs, 4)))  # fmt: skip
    _kernel.legs_fk(sk.parents, roots, rots, plan.offsets, plan.legs, plan.soles, ankles, qfeet, hips, sole)
    if type(ground) is PlaneGround:  # the same heights as its call, without a dozen numpy calls
        height, normal = np.empty((count, legs)), np.empty((count, legs, 3))
        _kernel.plane_query(sole, *ground.frame, height, normal)
    else:
        height, normal = ground(sole[..., 0], sole[..., 2])
        height = np.ascontiguousarray(np.broadcast_to(np.asarray(height, dtype=np.float64), (count, legs)))
        normal = np.ascontiguousarray(np.broadcast_to(np.asarray(normal, dtype=np.float64), (count, legs, 3)))
    shift = np.empty(count)
    finite = _kernel.ground_crowd(
        sk.parents, roots, rots, plan.offsets, plan.legs, plan.soles, plan.tips, plan.heels, plan.knees,
        sole, qfeet, ankles, hips, height, normal, weight,
        ALIGN_HEIGHT, CONTACT_HEIGHT, MAX_PELVIS_SHIFT, dt, plan.settings_array,
        points, weights, planted, stepping, yaw, animated, contacts, settle, shift,
    )  # fmt: skip
    if not finite:
        raise ValueError("ground query returned non-finite values")
    for req, value in zip(reqs, shift.tolist(), strict=True):
        req.pelvis_shift = value
    return True
