"""Compiled twins of the per-joint arithmetic of :mod:`engine.ragdoll._control`.

A fall puts some twenty ragdolls in the model (ten fallers and their walking neighbours): 260 ball
joints, 90 hinges, 400 actuators. Turning their commands into MuJoCo inputs was some sixty numpy
passes over those few hundred rows (each a microsecond of dispatch for nanoseconds of arithmetic),
2-3 ms of the fall's worst step; the twist projection after the step another twenty, reading the poses
back ten more. Here each is
one loop over the rows, written with the numpy path's operations in its order (the quaternion
helpers of :mod:`engine.jit`, sums left to right as numpy sums three or four terms, ``sin``,
``cos``, ``atan2`` and ``sqrt`` from the same C library): the same numbers bit for bit, which
``tests/engine/ragdoll/test_drive_kernel.py`` checks against the numpy path on a fall.
"""

from __future__ import annotations

import math

import numpy as np

from engine import jit
from engine.arrays import F64, I64, Bool
from engine.jit import qaxis_angle, qconj, qmul, qnormalize, qrot

__all__ = ["drive_kernel", "load", "read_kernel", "twist_kernel"]

_Q = tuple[float, float, float, float]
_V = tuple[float, float, float]


@jit.njit_inline
def _qlog(q: _Q) -> _V:
    """:func:`engine.quat.log`: normalised, in the ``w >= 0`` hemisphere, axis times angle."""
    q = qnormalize(q)
    if q[0] < 0.0:
        q = (-q[0], -q[1], -q[2], -q[3])
    s = math.sqrt(q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    angle = 2.0 * math.atan2(s, q[0])
    if s > 1e-12:
        return (q[1] / s * angle, q[2] / s * angle, q[3] / s * angle)
    return (angle, 0.0 * angle, 0.0 * angle)


@jit.njit_inline
def _qexp(r: _V) -> _Q:
    """:func:`engine.quat.exp`, with its series at tiny angles."""
    angle = math.sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2])
    half = 0.5 * angle
    k = math.sin(half) / angle if angle > 1e-9 else 0.5 - angle * angle / 48.0
    return (math.cos(half), r[0] * k, r[1] * k, r[2] * k)


@jit.njit_inline
def _hinge_angle(q: _Q, axis: _V) -> float:
    """:func:`engine.ragdoll._control.hinge_angles` of one rotation."""
    if q[0] < 0.0:
        q = (-q[0], -q[1], -q[2], -q[3])
    return 2.0 * math.atan2(q[1] * axis[0] + q[2] * axis[1] + q[3] * axis[2], q[0])


@jit.njit_inline
def _row4(a: F64, i: int) -> _Q:
    return (a[i, 0], a[i, 1], a[i, 2], a[i, 3])


@jit.njit_inline
def _row3(a: F64, i: int) -> _V:
    return (a[i, 0], a[i, 1], a[i, 2])


@jit.njit
def drive_kernel(
    dt: float,
    rows: I64,
    j: I64,
    c_root: F64,
    c_rot: F64,
    c_last_root: F64,
    c_last_rot: F64,
    c_has_last: Bool,
    c_muscle: F64,
    c_pin: F64,
    c_support: F64,
    c_kin: Bool,
    starts: I64,
    root_q: I64,
    root_d: I64,
    ball_src: I64,
    ball_owner: I64,
    ball_q: I64,
    ball_d: I64,
    ball_c: I64,
    ball_lead: F64,
    hinge_src: I64,
    hinge_owner: I64,
    hinge_q: I64,
    hinge_d: I64,
    hinge_c: I64,
    hinge_axis: F64,
    hinge_lead: F64,
    act: I64,
    act_owner: I64,
    act_kp: F64,
    act_kv: F64,
    body: I64,
    body_owner: I64,
    pin_eq: I64,
    pin_mocap: I64,
    consts: F64,
    body_mass: F64,
    gainprm: F64,
    biasprm: F64,
    eq_solref: F64,
    eq_active: Bool,
    ctrl: F64,
    mocap_pos: F64,
    mocap_quat: F64,
    xfrc: F64,
    qpos: F64,
    qvel: F64,
) -> None:
    """The servo targets, gains, pins, gravity support and kinematic placements of
    :func:`engine.ragdoll._control.apply_commands` for ragdolls ``rows`` (the layout's, in its
    order; ``j`` their flat joint rows in the command columns ``c_*``), written into MuJoCo's
    arrays. ``consts`` is ``(pin stiffness, pin damping, max lead, gravity)``."""
    stiff, damp, max_lead, gravity = consts[0], consts[1], consts[2], consts[3]
    for p in range(rows.shape[0]):
        i = rows[p]
        has, kin, pin = c_has_last[i], c_kin[i], c_pin[i]
        r0 = j[starts[p]]
        root, rot = _row3(c_root, i), _row4(c_rot, r0)
        last_root = _row3(c_last_root, i) if has else root
        last = _row4(c_last_rot, r0) if has else rot
        v = ((root[0] - last_root[0]) / dt, (root[1] - last_root[1]) / dt, (root[2] - last_root[2]) / dt)
        wr = qrot(last, _qlog(qmul(qconj(last), rot)))
        w = (wr[0] / dt, wr[1] / dt, wr[2] / dt)
        eq = pin_eq[p]
        eq_active[eq] = pin > 1e-4 and not kin
        eq_solref[eq, 0] = -stiff * pin
        eq_solref[eq, 1] = -damp * math.sqrt(pin)
        lead = min(damp / stiff / max(math.sqrt(pin), 0.2), max_lead)
        mc = pin_mocap[p]
        for c in range(3):
            mocap_pos[mc, c] = root[c] + v[c] * lead
        mocap_quat[mc, 0], mocap_quat[mc, 1], mocap_quat[mc, 2], mocap_quat[mc, 3] = qmul(
            _qexp((w[0] * lead, w[1] * lead, w[2] * lead)), rot
        )
        if kin:
            q, dq = root_q[p], root_d[p]
            for c in range(3):
                qpos[q + c] = root[c]
                qvel[dq + c] = v[c]
                qvel[dq + 3 + c] = w[c]
            for c in range(4):
                qpos[q + 3 + c] = rot[c]
    for k in range(ball_src.shape[0]):
        o = ball_owner[k]
        i, src = rows[o], j[ball_src[k]]
        ball = _row4(c_rot, src)
        last = _row4(c_last_rot, src) if c_has_last[i] else ball
        wl = _qlog(qmul(qconj(last), ball))
        w = (wl[0] / dt, wl[1] / dt, wl[2] / dt)
        lead = min(ball_lead[k] / max(math.sqrt(c_muscle[i]), 0.2), max_lead)
        target = _qlog(qmul(ball, _qexp((w[0] * lead, w[1] * lead, w[2] * lead))))
        c0 = ball_c[k]
        for c in range(3):
            ctrl[c0 + c] = target[c]
        if c_kin[i]:
            for c in range(4):
                qpos[ball_q[k] + c] = ball[c]
            for c in range(3):
                qvel[ball_d[k] + c] = w[c]
    for k in range(hinge_src.shape[0]):
        o = hinge_owner[k]
        i, src = rows[o], j[hinge_src[k]]
        axis = _row3(hinge_axis, k)
        hinge = _hinge_angle(_row4(c_rot, src), axis)
        last_h = _hinge_angle(_row4(c_last_rot, src), axis) if c_has_last[i] else hinge
        w_h = (hinge - last_h) / dt
        lead = min(hinge_lead[k] / max(math.sqrt(c_muscle[i]), 0.2), max_lead)
        ctrl[hinge_c[k]] = hinge + w_h * lead
        if c_kin[i]:
            qpos[hinge_q[k]] = hinge
            qvel[hinge_d[k]] = w_h
    for k in range(act.shape[0]):
        mw = c_muscle[rows[act_owner[k]]]
        a = act[k]
        gainprm[a, 0] = act_kp[k] * mw
        biasprm[a, 1] = -act_kp[k] * mw
        biasprm[a, 2] = -act_kv[k] * math.sqrt(mw)
    for k in range(body.shape[0]):
        b = body[k]
        for c in range(6):
            xfrc[b, c] = 0.0
        xfrc[b, 1] = body_mass[b] * gravity * c_support[rows[body_owner[k]]]


@jit.njit
def twist_kernel(ball_q: I64, ball_d: I64, ball_axis: F64, ball_twist: F64, qpos: F64, qvel: F64) -> None:
    """:func:`engine.ragdoll._control.project_twist` in place: each ball joint's twist about its bone
    clamped to ``±ball_twist``, and the twist velocity that pushes outwards removed."""
    for k in range(ball_q.shape[0]):
        qi, axis = ball_q[k], _row3(ball_axis, k)
        q = (qpos[qi], qpos[qi + 1], qpos[qi + 2], qpos[qi + 3])
        if q[0] < 0.0:
            q = (-q[0], -q[1], -q[2], -q[3])
        dot = q[1] * axis[0] + q[2] * axis[1] + q[3] * axis[2]
        t = (q[0], dot * axis[0], dot * axis[1], dot * axis[2])
        n = math.sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2] + t[3] * t[3])
        twist = (t[0] / n, t[1] / n, t[2] / n, t[3] / n) if n > 1e-9 else (1.0, 0.0, 0.0, 0.0)
        ang = 2.0 * math.atan2(twist[1] * axis[0] + twist[2] * axis[1] + twist[3] * axis[2], twist[0])
        limit = ball_twist[k]
        if not abs(ang) > limit:
            continue
        swing = qmul(q, qconj(twist))
        clamped = qaxis_angle(axis, min(max(ang, -limit), limit))
        qpos[qi], qpos[qi + 1], qpos[qi + 2], qpos[qi + 3] = qnormalize(qmul(swing, clamped))
        di = ball_d[k]
        rate = qvel[di] * axis[0] + qvel[di + 1] * axis[1] + qvel[di + 2] * axis[2]
        if np.sign(rate) == np.sign(ang):
            for c in range(3):
                qvel[di + c] = qvel[di + c] - rate * axis[c]


@jit.njit
def read_kernel(
    starts: I64,
    root_q: I64,
    ball_src: I64,
    ball_q: I64,
    hinge_src: I64,
    hinge_q: I64,
    hinge_axis: F64,
    qpos: F64,
    roots: F64,
    rot: F64,
) -> None:
    """:func:`engine.ragdoll._control.read_poses` into ``roots [P,3]`` and ``rot [ΣJ,4]``: the roots, the
    ball joints' rotations, the hinges' about their axes, the identity elsewhere, all normalised."""
    for f in range(rot.shape[0]):
        rot[f, 0], rot[f, 1], rot[f, 2], rot[f, 3] = 1.0, 0.0, 0.0, 0.0
    for p in range(root_q.shape[0]):
        q = root_q[p]
        for c in range(3):
            roots[p, c] = qpos[q + c]
        for c in range(4):
            rot[starts[p], c] = qpos[q + 3 + c]
    for k in range(ball_src.shape[0]):
        for c in range(4):
            rot[ball_src[k], c] = qpos[ball_q[k] + c]
    for k in range(hinge_src.shape[0]):
        h = hinge_src[k]
        rot[h, 0], rot[h, 1], rot[h, 2], rot[h, 3] = qaxis_angle(_row3(hinge_axis, k), qpos[hinge_q[k]])
    for f in range(rot.shape[0]):
        rot[f, 0], rot[f, 1], rot[f, 2], rot[f, 3] = qnormalize(_row4(rot, f))


def load() -> None:
    """Load the kernels now (from numba's disk cache, or compile them): called on zero rows, with arrays of
    the real ones' types, they do nothing but load. The physics world calls this when it compiles its
    model, so the first step that needs them (a crowd's first fall) does not pay the 20-50 ms."""
    i, f, f2, b = np.zeros(0, np.int64), np.zeros(0), np.zeros((0, 3)), np.zeros(0, np.bool_)
    drive_kernel(
        0.1, i, i, f2, f2, f2, f2, b, f, f, f, b, i, i, i, i, i, i, i, i, f, i, i, i, i, i, f2, f,
        i, i, f, f, i, i, i, i, f, f, f2, f2, f2, b, f, f2, f2, f2, f, f,
    )  # fmt: skip
    twist_kernel(i, i, f2, f, f, f)
    read_kernel(i, i, i, i, i, i, f2, f, f2, f2)
