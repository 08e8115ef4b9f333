"""Compiled kernels of :func:`engine.ik.grounding.ground_feet_batch`: a crowd's legs in three loops.

The batched grounding is a few dozen numpy calls over ``[P, L, …]`` arrays; each costs a
microsecond of dispatch for a hundred puppets' worth of nanoseconds. These are the same
steps as loops over puppets and legs, compiled by numba (:mod:`engine.jit`), in the three
pieces the Python between them needs:

1. :func:`legs_fk` — each puppet's leg FK, its ankles, feet, hips and soles (where the ground
   is asked about);
2. :func:`legs_targets` — after the ground query: each foot turned to the slope, its ankle
   target at the clip's clearance, lifted so no toe or heel is under the floor (the foot
   locks, which keep per-puppet state objects, run after this in numpy);
3. :func:`legs_solve` — the pelvis shift (lowest foot, then reach) and the two-bone solve
   of every leg, the float solver of :mod:`engine.ik._limb` operation for operation.

``tests/engine/ik/test_ground_kernel.py`` runs the grounding on both paths and compares.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from engine.jit import njit, qaxis_angle, qbetween, qconj, qmul, qnormalize, qrot, qslerp, vcross, vdot, vnorm, vunit

__all__ = [
    "BAD_GROUND",
    "BAD_WEIGHT",
    "DONE",
    "ground_crowd",
    "ground_crowd_on_plane",
    "legs_fk",
    "legs_solve",
    "legs_targets",
    "lock_group",
    "plane_query",
]

from engine.arrays import F64 as F
from engine.arrays import I64 as I

_EPS = 1e-9
DONE, BAD_WEIGHT, BAD_GROUND = 0, 1, 2  # what ground_crowd returns


@njit
def _v(a: F, i: int) -> tuple[float, float, float]:
    return (a[i, 0], a[i, 1], a[i, 2])


@njit
def _q(a: F, i: int) -> tuple[float, float, float, float]:
    return (a[i, 0], a[i, 1], a[i, 2], a[i, 3])


@njit
def _path_fk(parents: I, root: F, rot: F, off: F, pos: F, wrot: F, joint: int, chain: I) -> None:
    """:func:`_fk` of only ``joint`` and its ancestors (the same operations on that path; ``chain`` is scratch ``[J]``)."""
    n = 0
    j = joint
    while j > 0:
        chain[n] = j
        n += 1
        j = parents[j]
    for c in range(3):
        pos[0, c] = root[c]
    for c in range(4):
        wrot[0, c] = rot[0, c]
    for m in range(n - 1, -1, -1):
        j = chain[m]
        a = parents[j]
        pq = (wrot[a, 0], wrot[a, 1], wrot[a, 2], wrot[a, 3])
        d = qrot(pq, (off[j, 0], off[j, 1], off[j, 2]))
        pos[j, 0], pos[j, 1], pos[j, 2] = pos[a, 0] + d[0], pos[a, 1] + d[1], pos[a, 2] + d[2]
        wrot[j, 0], wrot[j, 1], wrot[j, 2], wrot[j, 3] = qmul(pq, (rot[j, 0], rot[j, 1], rot[j, 2], rot[j, 3]))


@njit
def legs_fk(
    parents: I, rows: I, roots: F, rots: F, offs: F, legs: I, soles: F, ankles: F, qfeet: F, hips: F, sole: F
) -> None:
    """Fill ``ankles``/``hips``/``sole [P,L,3]`` and ``qfeet [P,L,4]`` for legs ``legs [L,3]`` (upper, lower, foot)
    of the puppets whose poses are rows ``rows [P]`` of ``roots``/``rots`` (offsets ``offs [P, J, 3]``).

    Only each leg's own path (pelvis to foot) is walked: the same operations as the full FK on it."""
    n = rots.shape[1]
    pos, wrot, chain = np.empty((n, 3)), np.empty((n, 4)), np.empty(n, np.int64)
    for p in range(rows.shape[0]):
        r = rows[p]
        for k in range(legs.shape[0]):
            u, f = legs[k, 0], legs[k, 2]
            _path_fk(parents, roots[r], rots[r], offs[p], pos, wrot, f, chain)
            qf = _q(wrot, f)
            s = qrot(qf, _v(soles, k))
            for c in range(3):
                ankles[p, k, c] = pos[f, c]
                hips[p, k, c] = pos[u, c]
                sole[p, k, c] = pos[f, c] + s[c]
            for c in range(4):
                qfeet[p, k, c] = qf[c]


@njit
def plane_query(sole: F, point: F, normal: F, height: F, out_normal: F) -> None:
    """:class:`~engine.ik.grounding.PlaneGround` under every sole ``[P, L, 3]`` (its ``frame``:
    ``point``, unit ``normal``), the same operations as its numpy call: ``height [P, L]``,
    ``out_normal [P, L, 3]``."""
    for p in range(sole.shape[0]):
        for k in range(sole.shape[1]):
            x, z = sole[p, k, 0], sole[p, k, 2]
            height[p, k] = point[1] - (normal[0] * (x - point[0]) + normal[2] * (z - point[2])) / normal[1]
            for c in range(3):
                out_normal[p, k, c] = normal[c]


@njit
def _target_leg(
    sole: F,
    qfeet: F,
    height: F,
    normal: F,
    w: float,
    soles: F,
    tips: F,
    heels: F,
    align_height: float,
    contact_height: float,
    targets: F,
    new_rot: F,
    floor: F,
    p: int,
    k: int,
) -> None:
    """:func:`legs_targets` for leg ``k`` of puppet ``p`` (weight ``w``)."""
    ch = sole[p, k, 1]
    planted = min(max((align_height - ch) / (align_height - contact_height), 0.0), 1.0) * w
    nrm = (normal[p, k, 0], normal[p, k, 1], normal[p, k, 2])
    tilt = qbetween((0.0, 1.0, 0.0), nrm)
    r = qmul(qslerp((1.0, 0.0, 0.0, 0.0), tilt, planted), _q(qfeet[p], k))
    hw = height[p, k] * w
    so = qrot(r, _v(soles, k))
    t = (sole[p, k, 0] - so[0], hw + ch - so[1], sole[p, k, 2] - so[2])
    fl = (sole[p, k, 0], hw, sole[p, k, 2])
    toe, back = qrot(r, _v(tips, k)), qrot(r, _v(heels, k))
    n = ((1.0 - w) * 0.0 + w * nrm[0], (1.0 - w) * 1.0 + w * nrm[1], (1.0 - w) * 0.0 + w * nrm[2])
    nn = vnorm(n)
    n = (n[0] / nn, n[1] / nn, n[2] / nn)
    d_toe = vdot((t[0] + toe[0] - fl[0], t[1] + toe[1] - fl[1], t[2] + toe[2] - fl[2]), n)
    d_back = vdot((t[0] + back[0] - fl[0], t[1] + back[1] - fl[1], t[2] + back[2] - fl[2]), n)
    lift = max(0.0 - min(d_toe, d_back), 0.0) / n[1]
    targets[p, k, 0], targets[p, k, 1], targets[p, k, 2] = t[0], t[1] + lift, t[2]
    new_rot[p, k, 0], new_rot[p, k, 1], new_rot[p, k, 2], new_rot[p, k, 3] = r
    floor[p, k, 0], floor[p, k, 1], floor[p, k, 2] = fl


@njit
def legs_targets(
    sole: F,
    qfeet: F,
    height: F,
    normal: F,
    weight: F,
    soles: F,
    tips: F,
    heels: F,
    align_height: float,
    contact_height: float,
    targets: F,
    new_rot: F,
    floor: F,
) -> None:
    """Feet turned to the slope (``new_rot``), ankle ``targets`` at the clip's clearance over the ground
    and lifted out of it, and the ``floor`` point under each sole, all ``[P, L, …]``."""
    for p in range(sole.shape[0]):
        for k in range(sole.shape[1]):
            _target_leg(
                sole, qfeet, height, normal, weight[p], soles, tips, heels, align_height, contact_height,
                targets, new_rot, floor, p, k,
            )  # fmt: skip


@njit
def _angle(u: tuple[float, float, float], v: tuple[float, float, float]) -> float:
    return math.acos(min(max(vdot(vunit(u, _EPS), vunit(v, _EPS)), -1.0), 1.0))


@njit
def _about(
    point: tuple[float, float, float], centre: tuple[float, float, float], q: tuple[float, float, float, float]
) -> tuple[float, float, float]:
    d = qrot(q, (point[0] - centre[0], point[1] - centre[1], point[2] - centre[2]))
    return (centre[0] + d[0], centre[1] + d[1], centre[2] + d[2])


@njit
def _sub(a: tuple[float, float, float], b: tuple[float, float, float]) -> tuple[float, float, float]:
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


@njit
def _solve_limb(
    parents: I,
    pos: F,
    wrot: F,
    rot: F,
    ia: int,
    ib: int,
    ic: int,
    target: tuple[float, float, float],
    pole: tuple[float, float, float],
    end: tuple[float, float, float, float],
) -> None:
    """:func:`engine.ik._limb.solve_limb` with a pole and an end rotation, weight 1, on FK'd ``pos``/``wrot``;
    writes the three local rotations into ``rot``."""
    a, b, c = _v(pos, ia), _v(pos, ib), _v(pos, ic)
    qa, qb = _q(wrot, ia), _q(wrot, ib)
    pa = parents[ia]
    qpa = _q(wrot, pa) if pa >= 0 else (1.0, 0.0, 0.0, 0.0)
    lab = vnorm(_sub(b, a))
    lcb = vnorm(_sub(c, b))
    lat = min(max(vnorm(_sub(target, a)), abs(lab - lcb) + 1e-6), lab + lcb - 1e-6)
    ca, ba = _sub(c, a), _sub(b, a)
    normal = vcross(ca, ba)
    if vnorm(normal) < 1e-6 * max(lab * lcb, _EPS):
        fallback = vcross(ca, _sub(pole, a))
        if vnorm(fallback) < 1e-9:
            fallback = vcross(ca, (0.0, 0.0, 1.0))
        normal = fallback
    axis0 = vunit(normal, _EPS)
    ac_ab_0 = _angle(ca, ba)
    ba_bc_0 = _angle(_sub(a, b), _sub(c, b))
    ac_ab_1 = math.acos(min(max((lcb * lcb - lab * lab - lat * lat) / (-2.0 * lab * lat), -1.0), 1.0))
    ba_bc_1 = math.acos(min(max((lat * lat - lab * lab - lcb * lcb) / (-2.0 * lab * lcb), -1.0), 1.0))
    rb = qaxis_angle(axis0, ba_bc_1 - ba_bc_0)
    c = _about(c, b, rb)
    ra = qaxis_angle(axis0, ac_ab_1 - ac_ab_0)
    b, c = _about(b, a, ra), _about(c, a, ra)
    r1 = qbetween(_sub(c, a), _sub(target, a))
    b, c = _about(b, a, r1), _about(c, a, r1)
    root_turn = qmul(r1, ra)
    d = vunit(_sub(c, a), _EPS)
    pole_dir = _sub(pole, a)
    ba = _sub(b, a)
    s = vdot(ba, d)
    u = (ba[0] - s * d[0], ba[1] - s * d[1], ba[2] - s * d[2])
    s = vdot(pole_dir, d)
    v = (pole_dir[0] - s * d[0], pole_dir[1] - s * d[1], pole_dir[2] - s * d[2])
    ang = 0.0
    if vnorm(u) > 1e-9 and vnorm(v) > 1e-9:
        uu, vv = vunit(u, _EPS), vunit(v, _EPS)
        ang = math.atan2(vdot(vcross(uu, vv), d), vdot(uu, vv))
    r2 = qaxis_angle(d, ang)
    root_turn = qmul(r2, root_turn)
    new_qa = qmul(root_turn, qa)
    new_qb = qmul(root_turn, qmul(rb, qb))
    rot[ia, 0], rot[ia, 1], rot[ia, 2], rot[ia, 3] = qnormalize(qmul(qconj(qpa), new_qa))
    rot[ib, 0], rot[ib, 1], rot[ib, 2], rot[ib, 3] = qnormalize(qmul(qconj(new_qa), new_qb))
    rot[ic, 0], rot[ic, 1], rot[ic, 2], rot[ic, 3] = qnormalize(qmul(qconj(new_qb), end))


@njit
def _solve_puppet(
    parents: I,
    roots: F,
    rots: F,
    offs: F,
    legs: I,
    knees: F,
    targets: F,
    new_rot: F,
    ankles: F,
    hips: F,
    max_pelvis_shift: float,
    shift: F,
    p: int,
    r: int,
    pos: F,
    wrot: F,
    chain: I,
) -> None:
    """:func:`legs_solve` of puppet ``p``, whose pose is row ``r`` of ``roots``/``rots`` (``pos``/``wrot``/``chain``
    are scratch ``[J, …]``)."""
    low = math.inf
    for k in range(legs.shape[0]):
        low = min(low, targets[p, k, 1] - ankles[p, k, 1])
    s = min(max(low, -max_pelvis_shift), max_pelvis_shift)
    need_max = 0.0
    for k in range(legs.shape[0]):
        reach = vnorm(_v(offs[p], legs[k, 1])) + vnorm(_v(offs[p], legs[k, 2])) - 1e-4
        dx, dz = targets[p, k, 0] - hips[p, k, 0], targets[p, k, 2] - hips[p, k, 2]
        dxz = math.sqrt(dx * dx + dz * dz)
        dy = hips[p, k, 1] + s - targets[p, k, 1]
        need = dy - math.sqrt(max(reach * reach - dxz * dxz, 0.0)) if dxz < reach else 0.0
        need_max = max(need_max, max(need, 0.0))
    s = max(s - need_max, -max_pelvis_shift)
    shift[p] = s
    roots[r, 1] += s
    for k in range(legs.shape[0]):
        u, lo, f = legs[k, 0], legs[k, 1], legs[k, 2]
        _path_fk(parents, roots[r], rots[r], offs[p], pos, wrot, f, chain)
        pk = qrot(_q(wrot, parents[u]), _v(knees, k))
        pole = (pos[lo, 0] + pk[0], pos[lo, 1] + pk[1], pos[lo, 2] + pk[2])
        end = qnormalize(_q(new_rot[p], k))
        _solve_limb(parents, pos, wrot, rots[r], u, lo, f, _v(targets[p], k), pole, end)


@njit
def legs_solve(
    parents: I,
    roots: F,
    rots: F,
    offs: F,
    legs: I,
    knees: F,
    targets: F,
    new_rot: F,
    ankles: F,
    hips: F,
    max_pelvis_shift: float,
    shift: F,
) -> None:
    """Shift each pelvis (``roots`` and ``shift [P]`` written) and solve every leg onto its target, in place.

    A leg's solve reads the FK of its own path only (pelvis to foot): the other leg's joints,
    solved just before, are not on it."""
    n = rots.shape[1]
    pos, wrot, chain = np.empty((n, 3)), np.empty((n, 4)), np.empty(n, np.int64)
    for p in range(rots.shape[0]):
        _solve_puppet(
            parents, roots, rots, offs, legs, knees, targets, new_rot, ankles, hips, max_pelvis_shift, shift,
            p, p, pos, wrot, chain,
        )  # fmt: skip


@njit
def _smooth(w: float) -> float:
    return w * w * (3.0 - 2.0 * w)


@njit
def _lock_puppet(
    g: int,
    i: int,
    cg: int,
    st: bool,
    targets: F,
    new_rot: F,
    floor: F,
    tips: F,
    dt: float,
    settings: F,
    points: F,
    weights: F,
    planted: NDArray[np.bool_],
    stepping: NDArray[np.bool_],
    yaw: F,
    animated: F,
    contacts: F,
    toe: F,
    twist: F,
    gap: F,
    start: NDArray[np.bool_],
    still: NDArray[np.bool_],
    misplaced: NDArray[np.bool_],
) -> None:
    """:func:`lock_group` for one puppet: lock state row ``g``, targets row ``i``, contact votes row ``cg``,
    standing if ``st`` (``toe [L,3]`` and the ``[L]`` arrays after ``contacts`` are scratch)."""
    release_time, max_stretch, release_height, settle_gap = settings[0], settings[1], settings[2], settings[3]
    max_twist, settle_twist, step_time, step_height = settings[4], settings[5], settings[6], settings[7]
    legs = targets.shape[1]
    for k in range(legs):
        r = _q(new_rot[i], k)
        fwd = qrot(r, (0.0, 0.0, 1.0))
        y = math.atan2(fwd[0], fwd[2])
        held = yaw[g, k] if weights[g, k] > 0.0 else y
        tw = (held - y + math.pi) % (2 * math.pi) - math.pi
        r = qmul(qaxis_angle((0.0, 1.0, 0.0), tw * _smooth(weights[g, k])), r)
        new_rot[i, k, 0], new_rot[i, k, 1], new_rot[i, k, 2], new_rot[i, k, 3] = r
        yaw[g, k] = held
        twist[k] = abs(tw)
        tp = qrot(r, _v(tips, k))
        for c in range(3):
            toe[k, c] = targets[i, k, c] + tp[c]
        dx, dz = toe[k, 0] - animated[g, k, 0], toe[k, 2] - animated[g, k, 2]
        still[k] = math.sqrt(dx * dx + dz * dz) <= 0.1 * max(dt, 1e-9)
    any_stepping = False
    for k in range(legs):  # lock_feet, first pass: new locks, gaps, who must step
        w = weights[g, k]
        stepping[g, k] = stepping[g, k] and w > 0.0 and st
        any_stepping = any_stepping or stepping[g, k]
        down = contacts[cg, k] > 0.5
        start[k] = down and not planted[g, k] and not stepping[g, k]
        if start[k]:
            sw = _smooth(w)
            points[g, k, 0] = toe[k, 0] + sw * (points[g, k, 0] - toe[k, 0])
            points[g, k, 1] = toe[k, 1]
            points[g, k, 2] = toe[k, 2] + sw * (points[g, k, 2] - toe[k, 2])
            weights[g, k] = 1.0
        dx, dz = points[g, k, 0] - toe[k, 0], points[g, k, 2] - toe[k, 2]
        gap[k] = math.sqrt(dx * dx + dz * dz) + 0.15 * (0.0 if start[k] else twist[k])
        misplaced[k] = (
            (planted[g, k] or start[k]) and st and still[k] and (gap[k] > settle_gap or twist[k] > settle_twist)
        )
    far = 0.0
    for k in range(legs):
        far = max(far, gap[k] if misplaced[k] else 0.0)
    for k in range(legs):
        held = planted[g, k] or start[k]
        stretched = (gap[k] > max_stretch or twist[k] > max_twist) and not start[k] and not st
        if misplaced[k] and gap[k] >= far and not any_stepping:
            stepping[g, k] = True
        down = contacts[cg, k] > 0.5
        holding = down or (planted[g, k] and toe[k, 1] - floor[i, k, 1] < release_height)
        planted[g, k] = holding and not stretched and held and not stepping[g, k]
        w = weights[g, k]
        if not planted[g, k]:
            w = max(w - (dt / step_time if stepping[g, k] else dt / release_time), 0.0)
            weights[g, k] = w
        progress = 1.0 - w
        if stepping[g, k]:
            along = 1.0 - _smooth(min(max((progress - 0.25) / 0.5, 0.0), 1.0))
            lift = math.sin(math.pi * progress) * min(0.5 * gap[k] + 0.04, step_height)
        else:
            along = _smooth(w)
            lift = 4.0 * w * (1.0 - w) * min(0.5 * gap[k], step_height) if not planted[g, k] else 0.0
        placed_x = toe[k, 0] + along * (points[g, k, 0] - toe[k, 0])
        placed_z = toe[k, 2] + along * (points[g, k, 2] - toe[k, 2])
        targets[i, k, 0] += placed_x - toe[k, 0]
        targets[i, k, 1] += toe[k, 1] + lift - toe[k, 1]
        targets[i, k, 2] += placed_z - toe[k, 2]
        for c in range(3):
            animated[g, k, c] = toe[k, c]


@njit
def lock_group(
    idx: I,
    targets: F,
    new_rot: F,
    floor: F,
    tips: F,
    dt: float,
    settings: F,
    points: F,
    weights: F,
    planted: NDArray[np.bool_],
    stepping: NDArray[np.bool_],
    yaw: F,
    animated: F,
    contacts: F,
    settle: NDArray[np.bool_],
) -> None:
    """:func:`engine.ik.grounding._lock_group` and :func:`engine.ik.foot_lock.lock_feet` for puppets ``idx``
    (lock state ``[G, L, …]`` advanced in place; their ``targets``/``new_rot`` rows moved to the locks).

    ``settings`` is :meth:`FootLock.settings`: release time, max stretch, release height, settle gap,
    max twist, settle twist, step time, step height."""
    legs = targets.shape[1]
    toe = np.empty((legs, 3))
    twist, gap = np.empty(legs), np.empty(legs)
    start, still, misplaced = np.empty(legs, np.bool_), np.empty(legs, np.bool_), np.empty(legs, np.bool_)
    for g in range(idx.shape[0]):
        _lock_puppet(
            g, idx[g], g, settle[g], targets, new_rot, floor, tips, dt, settings, points, weights, planted, stepping,
            yaw, animated, contacts, toe, twist, gap, start, still, misplaced,
        )  # fmt: skip


@njit
def ground_crowd(
    parents: I,
    rows: I,
    roots: F,
    rots: F,
    offs: F,
    legs: I,
    soles: F,
    tips: F,
    heels: F,
    knees: F,
    sole: F,
    qfeet: F,
    ankles: F,
    hips: F,
    height: F,
    normal: F,
    weight: F,
    align_height: float,
    contact_height: float,
    max_pelvis_shift: float,
    dt: float,
    settings: F,
    lock_rows: I,
    points: F,
    weights: F,
    planted: NDArray[np.bool_],
    stepping: NDArray[np.bool_],
    yaw: F,
    animated: F,
    contact_rows: I,
    contacts: F,
    settle: NDArray[np.bool_],
    shift: F,
    kept: NDArray[np.bool_],
) -> int:
    """After :func:`legs_fk` and the ground query, the rest of a crowd's grounding in one pass:
    per puppet ``p`` :func:`legs_targets`, :func:`lock_group` (every puppet locked, one ``settings``)
    and :func:`legs_solve`, in place on its pose, row ``rows[p]`` of ``roots``/``rots``, and its lock
    state, row ``lock_rows[p]`` of the lock arrays (its votes: row ``contact_rows[p]`` of ``contacts``).
    Toe tips are per puppet, ``tips [P, L, 3]``, as offsets are: puppets of one hierarchy with bones
    of their own (the snowmen, each fitted to its balls) are one crowd.
    A puppet whose result is not finite keeps its given pose and is marked in ``kept [P]`` (its
    ``shift`` and lock state still advance, as on the path in pieces). Returns :data:`DONE`, or, changing
    nothing, :data:`BAD_WEIGHT` if a ``weight`` is outside ``0..1`` (checked first) or :data:`BAD_GROUND` if the
    ground's ``height``/``normal`` are not all finite."""
    count, n, nl = rows.shape[0], rots.shape[1], legs.shape[0]
    for p in range(count):
        if weight[p] < 0.0 or weight[p] > 1.0:
            return BAD_WEIGHT
    for p in range(count):
        for k in range(nl):
            if not math.isfinite(height[p, k]):
                return BAD_GROUND
            for c in range(3):
                if not math.isfinite(normal[p, k, c]):
                    return BAD_GROUND
    targets, new_rot, floor = np.empty((count, nl, 3)), np.empty((count, nl, 4)), np.empty((count, nl, 3))
    pos, wrot, chain = np.empty((n, 3)), np.empty((n, 4)), np.empty(n, np.int64)
    toe = np.empty((nl, 3))
    twist, gap = np.empty(nl), np.empty(nl)
    start, still, misplaced = np.empty(nl, np.bool_), np.empty(nl, np.bool_), np.empty(nl, np.bool_)
    given_root, given_rot = np.empty(3), np.empty((n, 4))
    for p in range(count):
        r = rows[p]
        for k in range(nl):
            _target_leg(
                sole, qfeet, height, normal, weight[p], soles, tips[p], heels, align_height, contact_height,
                targets, new_rot, floor, p, k,
            )  # fmt: skip
        _lock_puppet(
            lock_rows[p], p, contact_rows[p], settle[p], targets, new_rot, floor, tips[p], dt, settings, points, weights,
            planted, stepping, yaw, animated, contacts, toe, twist, gap, start, still, misplaced,
        )  # fmt: skip
        given_root[:] = roots[r]
        given_rot[:, :] = rots[r]
        _solve_puppet(
            parents, roots, rots, offs, legs, knees, targets, new_rot, ankles, hips, max_pelvis_shift, shift,
            p, r, pos, wrot, chain,
        )  # fmt: skip
        finite = True
        for c in range(3):
            finite = finite and math.isfinite(roots[r, c])
        for j in range(n):
            for c in range(4):
                finite = finite and math.isfinite(rots[r, j, c])
        kept[p] = not finite
        if not finite:
            roots[r] = given_root
            rots[r] = given_rot
    return DONE


@njit
def ground_crowd_on_plane(
    parents: I,
    rows: I,
    roots: F,
    rots: F,
    offs: F,
    legs: I,
    soles: F,
    tips: F,
    heels: F,
    knees: F,
    point: F,
    plane_normal: F,
    weight: F,
    align_height: float,
    contact_height: float,
    max_pelvis_shift: float,
    dt: float,
    settings: F,
    lock_rows: I,
    points: F,
    weights: F,
    planted: NDArray[np.bool_],
    stepping: NDArray[np.bool_],
    yaw: F,
    animated: F,
    contact_rows: I,
    contacts: F,
    settle: NDArray[np.bool_],
    shift: F,
    kept: NDArray[np.bool_],
) -> int:
    """:func:`legs_fk`, :func:`plane_query` (the plane through ``point`` with unit ``plane_normal``) and
    :func:`ground_crowd` (``tips [P, L, 3]``) in one call: a crowd on flat ground grounded with one dispatch from Python and its
    scratch arrays made here (the same functions, so the same operations). Returns what :func:`ground_crowd` does."""
    count, nl = rows.shape[0], legs.shape[0]
    ankles, hips, sole = np.empty((count, nl, 3)), np.empty((count, nl, 3)), np.empty((count, nl, 3))
    qfeet = np.empty((count, nl, 4))
    legs_fk(parents, rows, roots, rots, offs, legs, soles, ankles, qfeet, hips, sole)
    height, normal = np.empty((count, nl)), np.empty((count, nl, 3))
    plane_query(sole, point, plane_normal, height, normal)
    return ground_crowd(
        parents, rows, roots, rots, offs, legs, soles, tips, heels, knees, sole, qfeet, ankles, hips, height, normal,
        weight, align_height, contact_height, max_pelvis_shift, dt, settings, lock_rows, points, weights, planted,
        stepping, yaw, animated, contact_rows, contacts, settle, shift, kept,
    )  # fmt: skip
