"""The IK stage's crowd pass: a crowd's feet planted in two compiled calls, no Python per puppet.

:func:`~engine.ik.grounding.ground_feet_batch` already grounds a crowd of one skeleton on
compiled kernels, but around them the stage did Python per puppet every step: grouping the
requests, stacking offsets, fitting and grouping the foot locks, reading their state from
the components, writing the pelvis shifts back. That cost several times the kernels. Here
a :class:`CrowdPlan` is made once per membership: the puppets that only ask to have their
feet planted (no effectors, no hands), share one joint hierarchy and have live foot locks of one
tuning — from one puppet up. Bone lengths and toe tips ride per member in the kernel's arrays, so
puppets fitted to their own bones (the snowman game's snowmen, each rigged to its balls) share
the pass with the default puppets. The plan holds while none of the fields it was made from was
assigned since (the fields' assignment logs, :func:`engine.columns.assignment_mark`: no look at
the members at all); after an assignment it is checked with a handful of C-level passes over the
members (``map``/``all``, no Python frame per puppet). Each step then runs
:func:`~engine.ik._ground_kernel.legs_fk`, the ground query, and
:func:`~engine.ik._ground_kernel.ground_crowd` (on flat ground the three in one compiled call,
:func:`~engine.ik._ground_kernel.ground_crowd_on_plane`) on the columns themselves, at the members'
rows (:meth:`engine.columns.Column.rows`: the crowd may be part of the animation's batch, with
one puppet in the air or ten fallen): the local poses and the foot locks' state are updated
in place.

The arithmetic is the compiled path's of :func:`~engine.ik.grounding.ground_feet_batch`
operation for operation (the same kernel helpers), which is also the one-puppet float path
of :func:`~engine.ik.grounding.ground_feet`, so states hash the same whichever path a puppet
took before. Whatever the plan cannot vouch for (a member with hands on a sphere, a lock not
yet fitted, numba off) is left to the general path of :func:`engine.ik.system.ik_system`,
puppet by puppet: the rest of the crowd stays on the pass.
"""

from __future__ import annotations

from collections import Counter, deque
from dataclasses import dataclass
from itertools import repeat
from operator import attrgetter, is_
from typing import Any

import numpy as np
from numpy.typing import NDArray

from engine import jit
from engine.arrays import F64 as F
from engine.arrays import I64
from engine.columns import Columns, Mark, assignment_mark, unassigned_since
from engine.components import LocalPose, Puppet
from engine.fk import kernel_array
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
_WEIGHT = attrgetter("grounding_weight")
_SETTLE = attrgetter("settle")
#: What a member's request, puppet and lock must keep for the plan to hold (compared as tuples, in C).
_REQUEST_FIELDS = ("grounding", "effectors", "sphere_centre", "foot_lock")
_PUPPET_FIELDS = ("skeleton", "offsets")
_TUNING_FIELDS = (
    "enabled",
    "release_time",
    "max_stretch",
    "release_height",
    "settle_gap",
    "max_twist",
    "settle_twist",
    "step_time",
    "step_height",
)
_REQUEST = attrgetter(*_REQUEST_FIELDS[1:])
_PUPPET = attrgetter(*_PUPPET_FIELDS)
_TUNING = attrgetter(*_TUNING_FIELDS)
Marks = tuple[Mark | None, ...]


def _mark(requests: list[Any]) -> Marks | None:
    """Where the assignment logs (:func:`engine.columns.assignment_mark`) of every field :func:`_holds` reads stand
    now: the requests' ``grounding``, ``effectors``, ``sphere_centre`` and ``foot_lock``, the puppets' ``skeleton``
    and ``offsets``, the locks' tuning and ``contacts`` (what :func:`_plain` asks of an outsider); ``None`` when the
    requests are of several classes or a field cannot have a log (then every step compares the members)."""
    kinds = set(map(type, requests))
    if len(kinds) != 1:
        return None
    marks = (
        assignment_mark(kinds.pop(), _REQUEST_FIELDS),
        assignment_mark(Puppet, _PUPPET_FIELDS),
        assignment_mark(FootLock, (*_TUNING_FIELDS, "contacts")),
    )
    return None if None in marks else marks


def _unassigned(marks: Marks | None) -> bool:
    """Whether none of the fields marked by :func:`_mark` was assigned since."""
    return marks is not None and all(map(unassigned_since, marks))


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


def _own_tuning(req: Any) -> tuple[float, ...] | None:
    """The tuning of ``req``'s lock if the request is plain with it (:func:`_plain`), else ``None``."""
    lock = req.foot_lock
    return lock.settings() if lock is not None and _plain(req, lock.settings()) else None


def _unchanged(now: list[Any], then: list[Any]) -> bool:
    """``now == then`` for lists of field tuples, where a field that is not the same object may be an
    array (whose ``==`` cannot say): every field is the same object or an equal plain value."""
    try:
        return now == then
    except ValueError:  # an array compared with something else: it was replaced
        return False


@dataclass
class CrowdPlan:
    """Who the crowd pass serves, and what it checks every step that they still are.

    Attributes:
        table: the world's query result the plan was made for (the ECS hands out the same
            list until an entity or component of the query changes; kept so its id is not reused).
        all_requests, grounding: every row's request and its ``grounding`` flag then (a puppet
            that jumps changes the plan).
        rows: the members' positions in ``table`` (none: no crowd, everyone takes the general path).
        outsiders: the requests of the rest of the members' group (alike puppets that only ask
            to be grounded, but not plain: hands on a sphere, no contact votes); one that becomes
            plain changes the plan.
        skeleton, puppets: their shared hierarchy (the first such skeleton seen) and their ``Puppet``
            components; ``puppet_fields`` each member's ``(skeleton, offsets)`` objects, ``offsets`` their
            stack ``[P, J, 3]`` and ``tips`` their own skeletons' toe tips ``[P, L, 3]``.
        alike: per member, how many puppets of its very skeleton (``same_as``) ask to be grounded alike:
            the path it would take off the pass (:data:`engine.ik.system.BATCH` or more: batched),
            which says whether a non-finite result marks it unreached.
        locals_, requests, locks: the members' components, in row order (tuples: the columns
            remember their rows by the tuple); ``request_fields`` each request's
            ``(effectors, sphere_centre, foot_lock)``.
        settings, tuning, settings_array: the locks' tuning (:meth:`FootLock.settings`), one for all;
            ``tuning`` with ``enabled`` first, as each lock must still read.
        checked: the row arrays of the members' columns last found to agree (:func:`ground_crowd`).
        marks: where the assignment logs of the fields the plan depends on stood when it was last found to hold
            (:func:`_mark`): while none of them was assigned since, it still holds without a look at the members.
    """

    table: list[tuple[Any, ...]]
    all_requests: list[Any]
    grounding: list[bool]
    rows: list[int]
    outsiders: list[Any]
    skeleton: Skeleton | None
    puppets: list[Puppet]
    puppet_fields: list[tuple[Any, ...]]
    offsets: F
    locals_: tuple[LocalPose, ...]
    requests: list[Any]
    request_fields: list[tuple[Any, ...]]
    locks: tuple[FootLock, ...]
    settings: tuple[float, ...]
    tuning: tuple[Any, ...]
    settings_array: F
    legs: I64
    soles: F
    tips: F
    heels: F
    knees: F
    alike: I64
    checked: tuple[I64, ...] = ()
    marks: Marks | None = None


def plan_crowd(table: list[tuple[Any, ...]], kin: Any, same_as: Any, crowd_from: int) -> CrowdPlan:
    """The crowd of ``table`` (rows ``(entity, Puppet, LocalPose, IKRequest)``).

    It is the plain members of the largest group of rows that ask for grounding and no effectors and
    whose skeletons share one hierarchy (``kin`` maps a skeleton to the first seen with the same joints
    and parents; their bone lengths and toe tips may differ): no hands on a sphere, a live foot lock,
    the first plain member's lock tuning; at least ``crowd_from`` of them. Otherwise the plan has no
    members and only remembers that there is no crowd. ``same_as`` (a skeleton's canonical equal)
    counts each member's :attr:`CrowdPlan.alike`."""
    requests = [row[3] for row in table]
    groups: dict[int, list[int]] = {}
    for i, (_, puppet, _, req) in enumerate(table):
        if req.grounding and not req.effectors:
            groups.setdefault(id(kin(puppet.skeleton)), []).append(i)
    group = max(groups.values(), key=len) if groups else []
    equal = {i: id(same_as(table[i][1].skeleton)) for i in group}
    alike = Counter(equal.values())
    settings = next((t for i in group if (t := _own_tuning(table[i][3])) is not None), ())
    rows = [i for i in group if _plain(table[i][3], settings)]
    members_set = set(rows)
    outsiders = [table[i][3] for i in group if i not in members_set]
    if len(rows) < crowd_from:
        rows, outsiders = [], []
    puppets: list[Puppet] = [table[i][1] for i in rows]
    members = [table[i][3] for i in rows]
    locks = tuple(req.foot_lock for req in members)
    sk = kin(puppets[0].skeleton) if puppets else None
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
        outsiders=outsiders,
        skeleton=sk,
        puppets=puppets,
        puppet_fields=list(map(_PUPPET, puppets)),
        offsets=np.array([p.joint_offsets() for p in puppets], dtype=np.float64),
        locals_=tuple(table[i][2] for i in rows),
        requests=members,
        request_fields=list(map(_REQUEST, members)),
        locks=locks,
        settings=settings,
        tuning=(True, *settings),
        settings_array=np.array(settings, dtype=np.float64),
        legs=idx,
        soles=np.array([leg.sole for leg in legs], dtype=np.float64),
        tips=np.array([p.skeleton.tips[idx[:, 2]] for p in puppets], dtype=np.float64).reshape(-1, len(legs), 3),
        heels=np.array([leg.heel for leg in legs], dtype=np.float64),
        knees=np.array([leg.knee_forward for leg in legs], dtype=np.float64),
        alike=np.array([alike[equal[i]] for i in rows], dtype=np.int64),
        marks=_mark(requests),
    )


def _holds(plan: CrowdPlan, table: list[tuple[Any, ...]]) -> bool:
    """Whether ``plan`` still describes ``table``'s crowd this step.

    While no field the plan depends on was assigned since it was last found to hold (:func:`_mark`), it holds with
    no look at the members: a steady crowd costs no Python per puppet. Otherwise it is checked with C-level passes
    over the members (Python only for the outsiders, the few unusual puppets of the group), and marked again if it
    holds. A puppet outside the group that becomes fit to join it without its ``grounding`` flag changing (its
    effectors cleared, say) is noticed at the next change of membership; until then it is served, correctly, by
    the general path."""
    if table is not plan.table:
        return False
    if _unassigned(plan.marks):
        return True
    if list(map(_GROUNDING, plan.all_requests)) != plan.grounding:
        return False
    holds = not plan.rows or (
        _unchanged(list(map(_REQUEST, plan.requests)), plan.request_fields)
        and _unchanged(list(map(_PUPPET, plan.puppets)), plan.puppet_fields)
        and list(map(_TUNING, plan.locks)).count(plan.tuning) == len(plan.locks)
        and not any(_plain(req, plan.settings) for req in plan.outsiders)
    )
    if holds:
        plan.marks = _mark(plan.all_requests)
    return holds


def current_plan(
    plan: CrowdPlan | None, table: list[tuple[Any, ...]], kin: Any, same_as: Any, crowd_from: int
) -> CrowdPlan:
    """``plan`` if it still holds for ``table``, else a new one (:func:`plan_crowd`)."""
    if plan is not None and _holds(plan, table):
        return plan
    return plan_crowd(table, kin, same_as, crowd_from)


def _place(cols: Columns, ctype: type, name: str, key: int, owners: tuple[Any, ...], shape: tuple[int, ...],
           dtype: type = np.float64) -> tuple[NDArray[Any], I64] | None:  # fmt: skip
    """The column of field ``name`` of ``owners`` and their rows in it (:meth:`~engine.columns.Column.rows`),
    the column made theirs first if one of them is not in it; ``None`` unless every field has ``shape``."""
    column = cols.get(ctype, name, key, dtype)
    found = column.rows(owners)
    if found is None:
        try:
            column.read(owners)
        except ValueError:  # ragged fields: some lock not fitted yet
            return None
        found = column.rows(owners)
    if found is None or found[0].shape[1:] != shape or not found[0].flags.c_contiguous:
        return None
    return found


def ground_crowd(plan: CrowdPlan, cols: Columns, ground: GroundQuery, dt: float) -> NDArray[np.bool_] | None:
    """Plant the feet of ``plan``'s crowd (a plan that holds this step: :func:`current_plan`) in place,
    if numba runs and every member's pose and lock state can be in their columns (fields replaced
    by other code are taken in, as a column read does); ``None`` (nothing done) otherwise. Writes
    each member's ``pelvis_shift``; returns which members kept their given pose (a result that was
    not finite)."""
    sk, reqs, locks = plan.skeleton, plan.requests, plan.locks
    if sk is None or not jit.enabled():
        return None
    joints, legs = sk.num_joints, len(plan.legs)
    roots = _place(cols, LocalPose, "root", joints, plan.locals_, (3,))
    rots = _place(cols, LocalPose, "rotations", joints, plan.locals_, (joints, 4))
    contacts = _place(cols, FootLock, "contacts", legs, locks, (legs,))
    if roots is None or rots is None or contacts is None:
        return None
    state: list[tuple[NDArray[Any], I64]] = []
    for name in _LOCK_STATE:
        found = _place(cols, FootLock, name, legs, locks, (legs, 3) if name in ("points", "animated") else (legs,),
                       _LOCK_TYPES.get(name, np.float64))  # fmt: skip
        if found is None:
            return None
        state.append(found)
    index = (roots[1], rots[1], *(found[1] for found in state))
    if not (len(index) == len(plan.checked) and all(map(is_, index, plan.checked))):
        # The poses' two columns, and the locks' six, must hold the members at the same rows; the row
        # arrays stay the same objects while the columns keep their rows, so this is checked once.
        if not (np.array_equal(index[0], index[1]) and all(np.array_equal(index[2], i) for i in index[3:])):
            return None
        plan.checked = index
    count = len(reqs)
    weight = np.fromiter(map(_WEIGHT, reqs), dtype=np.float64, count=count)
    settle = np.fromiter(map(_SETTLE, locks), dtype=np.bool_, count=count)
    rows = roots[1]
    shift, kept = np.empty(count), np.empty(count, dtype=np.bool_)
    points, weights, planted, stepping, yaw, animated = (found[0] for found in state)
    if type(ground) is PlaneGround:  # the same heights as its call, in the same dispatch as the rest
        status = _kernel.ground_crowd_on_plane(
            sk.parents, rows, roots[0], rots[0], plan.offsets, plan.legs, plan.soles, plan.tips, plan.heels,
            plan.knees, *ground.frame, weight, ALIGN_HEIGHT, CONTACT_HEIGHT, MAX_PELVIS_SHIFT, dt,
            plan.settings_array, state[0][1], points, weights, planted, stepping, yaw, animated, contacts[1],
            contacts[0], settle, shift, kept,
        )  # fmt: skip
    else:
        ankles, hips, sole, qfeet = (np.empty((count, legs, 3)), np.empty((count, legs, 3)),
                                     np.empty((count, legs, 3)), np.empty((count, legs, 4)))  # fmt: skip
        _kernel.legs_fk(sk.parents, rows, roots[0], rots[0], plan.offsets, plan.legs, plan.soles, ankles, qfeet, hips,
                        sole)  # fmt: skip
        height, normal = ground(sole[..., 0], sole[..., 2])
        height, normal = kernel_array(height, (count, legs)), kernel_array(normal, (count, legs, 3))
        status = _kernel.ground_crowd(
            sk.parents, rows, roots[0], rots[0], plan.offsets, plan.legs, plan.soles, plan.tips, plan.heels,
            plan.knees, sole, qfeet, ankles, hips, height, normal, weight,
            ALIGN_HEIGHT, CONTACT_HEIGHT, MAX_PELVIS_SHIFT, dt, plan.settings_array,
            state[0][1], points, weights, planted, stepping, yaw, animated, contacts[1], contacts[0], settle, shift,
            kept,
        )  # fmt: skip
    if status == _kernel.BAD_WEIGHT:
        raise ValueError("weight must lie in 0..1")
    if status == _kernel.BAD_GROUND:
        raise ValueError("ground query returned non-finite values")
    deque(map(setattr, reqs, repeat("pelvis_shift"), shift.tolist()), maxlen=0)
    return kept
