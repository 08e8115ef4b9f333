"""Applying ragdoll commands and reading poses back, batched over every ragdoll.

A ragdoll's command is what it should do (target pose, weights, hold, kinematic placement)
plus the target it had last step, from which target velocities follow; all of them are the
columns of :class:`~engine.ragdoll._commands.Commands`. :func:`apply_commands` turns the
commands of the ragdolls in the model into MuJoCo inputs in one vectorised pass over the flat
:class:`~engine.ragdoll._layout.Layout`; :func:`project_twist` enforces the
ball joints' twist limits; :func:`read_poses` gathers every ragdoll's pose.
"""

from __future__ import annotations

import mujoco
import numpy as np
from numpy.typing import NDArray

from engine import jit, quat
from engine.arrays import F64 as _F
from engine.arrays import I64
from engine.ragdoll._commands import Commands, joint_rows
from engine.ragdoll._contact_bits import set_contact_bits
from engine.ragdoll._drive_kernel import drive_kernel, read_kernel, twist_kernel
from engine.ragdoll._layout import Layout
from engine.ragdoll.mjcf import ANIMATED_BITS, GHOST_BITS, SIMULATED_BITS

__all__ = ["apply_commands", "place", "project_twist", "read_poses", "hinge_angles", "GRAVITY"]

GRAVITY = 9.81
_PIN_STIFFNESS = 2500.0  # weld reference stiffness (1/s²) at pin weight 1
_PIN_DAMPING = 100.0  # and damping (1/s): critically damped
_MAX_LEAD = 0.5  # s: cap on the velocity lead at tiny weights
_CONSTS = np.array([_PIN_STIFFNESS, _PIN_DAMPING, _MAX_LEAD, GRAVITY])  # drive_kernel's constants
_HOLD_REACH = 0.5  # m: farthest the hold spring's anchor is from the held body (a stick flicked into the sky)


def hinge_angles(rot: _F, axes: _F) -> _F:
    """Signed angle about each hinge axis of (hemisphere-aligned) quaternions."""
    h = quat.align_hemisphere(rot)
    return 2.0 * np.arctan2(np.sum(h[..., 1:] * axes, axis=-1), h[..., 0])


def apply_commands(
    L: Layout,
    m: mujoco.MjModel,
    d: mujoco.MjData,
    C: Commands,
    rows: I64,
    dt: float,
    ghost: NDArray[np.bool_] | None = None,
) -> None:
    """Turn the commands of ragdolls ``rows`` (the layout's ragdolls, in its order) into servo targets,
    gains, pins, holds and placements (``ghost [P]``: which simulated ragdolls pass through other
    ragdolls this step); their targets then become their last targets."""
    if not len(rows):
        return
    j = joint_rows(C.starts, rows)
    if jit.enabled():
        drive_kernel(
            dt, rows, j, C.root, C.rot, C.last_root, C.last_rot, C.has_last, C.muscle, C.pin, C.support,
            C.kinematic, L.starts, L.root_q, L.root_d, L.ball_src, L.ball_owner, L.ball_q, L.ball_d, L.ball_c,
            L.ball_lead, L.hinge_src, L.hinge_owner, L.hinge_q, L.hinge_d, L.hinge_c, L.hinge_axis, L.hinge_lead,
            L.act, L.act_owner, L.act_kp, L.act_kv, L.body, L.body_owner, L.pin_eq, L.pin_mocap, _CONSTS,
            m.body_mass, m.actuator_gainprm, m.actuator_biasprm, m.eq_solref, d.eq_active, d.ctrl,
            d.mocap_pos, d.mocap_quat, d.xfrc_applied, d.qpos, d.qvel,
        )  # fmt: skip
    else:
        _drive(L, m, d, C, rows, j, dt)
    kin = C.kinematic[rows]
    ghost = np.zeros(len(rows), dtype=bool) if ghost is None else ghost
    # An animated (kinematic) ragdoll touches only simulated bodies and props: not the
    # ground (neither can give way), not other animated bodies and not itself -- a
    # crouching pose lays the arms into the legs, and the contact impulses inside the
    # substeps would spin the arms and fling the ball in their hands. A ghost (deep in another
    # ragdoll) touches only the ground and props until it is out (mjcf.GHOST_BITS).
    kind = np.where(kin, 1, np.where(ghost, 2, 0))[L.geom_owner]
    bits = np.array([SIMULATED_BITS, ANIMATED_BITS, GHOST_BITS])[kind]
    set_contact_bits(m, L.geom, bits[:, 0], bits[:, 1])
    # holds: every hold constraint off and every anchor on its target, then Python only for the held few
    d.eq_active[L.hold_eqs] = 0
    d.mocap_pos[L.hold_mocap] = C.hold_target[rows]
    for p, i in enumerate(rows.tolist()):
        hold = C.hold[i]
        if hold is None:
            continue
        d.eq_active[L.hold_eq[p][hold]] = 1
        target = C.hold_target[i]  # the spring pulls from at most _HOLD_REACH away: a bounded force
        held = d.xpos[L.body[L.starts[p] + L.hold_joint[p][hold]]]
        gap = target - held
        dist = float(np.linalg.norm(gap))
        if dist > _HOLD_REACH:
            target = held + gap * (_HOLD_REACH / dist)
        d.mocap_pos[L.hold_mocap[p]] = target
    C.roll(rows, keep_prev=False)


def _drive(L: Layout, m: mujoco.MjModel, d: mujoco.MjData, C: Commands, rows: I64, j: I64, dt: float) -> None:
    """The numpy path of :func:`engine.ragdoll._drive_kernel.drive_kernel` (its reference): servo targets
    with their velocity lead, gains, pins, gravity support and the kinematic ragdolls' placements."""
    has = C.has_last[rows]
    root, rot = C.root[rows], C.rot[j]
    last_root = np.where(has[:, None], C.last_root[rows], root)
    last_rot = np.where(np.repeat(has, C.joints[rows])[:, None], C.last_rot[j], rot)
    muscle, pin, kin = C.muscle[rows], C.pin[rows], C.kinematic[rows]
    r0 = L.starts[:-1]
    # target velocities from the previous target (zero after a placement)
    v_root = (root - last_root) / dt
    w_root = quat.rotate(last_rot[r0], quat.log(quat.mul(quat.conjugate(last_rot[r0]), rot[r0]))) / dt
    ball, hinge = rot[L.ball_src], hinge_angles(rot[L.hinge_src], L.hinge_axis)
    w_ball = quat.log(quat.mul(quat.conjugate(last_rot[L.ball_src]), ball)) / dt
    w_hinge = (hinge - hinge_angles(last_rot[L.hinge_src], L.hinge_axis)) / dt
    # PD servos without a velocity input trail a moving target by kv/kp seconds; leading
    # the command by that time along the target's velocity equals a PD with a velocity
    # target to first order (≈15° less error on a walking thigh).
    weak = np.maximum(np.sqrt(muscle), 0.2)
    lead_b = np.minimum(L.ball_lead / weak[L.ball_owner], _MAX_LEAD)
    lead_h = np.minimum(L.hinge_lead / weak[L.hinge_owner], _MAX_LEAD)
    d.ctrl[L.ball_c[:, None] + np.arange(3)] = quat.log(quat.mul(ball, quat.exp(w_ball * lead_b[:, None])))
    d.ctrl[L.hinge_c] = hinge + w_hinge * lead_h
    mw = muscle[L.act_owner]
    m.actuator_gainprm[L.act, 0] = L.act_kp * mw
    m.actuator_biasprm[L.act, 1] = -L.act_kp * mw
    m.actuator_biasprm[L.act, 2] = -L.act_kv * np.sqrt(mw)
    # an animated ragdoll is placed on its target every step and its servos hold the pose inside
    # the step: its pin would add nothing but a weld to solve (six constraint rows, an island of
    # its own) for each animated puppet standing near a fall
    d.eq_active[L.pin_eq] = (pin > 1e-4) & ~kin
    m.eq_solref[L.pin_eq] = np.stack([-_PIN_STIFFNESS * pin, -_PIN_DAMPING * np.sqrt(pin)], axis=1)
    pin_lead = np.minimum(_PIN_DAMPING / _PIN_STIFFNESS / np.maximum(np.sqrt(pin), 0.2), _MAX_LEAD)
    d.mocap_pos[L.pin_mocap] = root + v_root * pin_lead[:, None]
    d.mocap_quat[L.pin_mocap] = quat.mul(quat.exp(w_root * pin_lead[:, None]), rot[r0])
    d.xfrc_applied[L.body] = 0.0
    d.xfrc_applied[L.body, 1] = m.body_mass[L.body] * GRAVITY * C.support[rows][L.body_owner]
    if kin.any():
        k = np.nonzero(kin)[0]
        d.qpos[L.root_q[k, None] + np.arange(3)] = root[k]
        d.qpos[L.root_q[k, None] + np.arange(3, 7)] = rot[r0[k]]
        d.qvel[L.root_d[k, None] + np.arange(3)] = v_root[k]
        d.qvel[L.root_d[k, None] + np.arange(3, 6)] = w_root[k]
        b, h = kin[L.ball_owner], kin[L.hinge_owner]
        d.qpos[L.ball_q[b, None] + np.arange(4)] = ball[b]
        d.qvel[L.ball_d[b, None] + np.arange(3)] = w_ball[b]
        d.qpos[L.hinge_q[h]] = hinge[h]
        d.qvel[L.hinge_d[h]] = w_hinge[h]


def _ranges(lo: I64, hi: I64) -> I64:
    """``lo[0]..hi[0]``, ``lo[1]..hi[1]``, … end to end (half-open ranges) as one index array."""
    counts = hi - lo
    total = int(counts.sum())
    first = np.repeat(lo - np.concatenate([[0], np.cumsum(counts)[:-1]]), counts)
    return np.asarray(first + np.arange(total), dtype=np.int64)


def place(
    L: Layout,
    d: mujoco.MjData,
    ordinals: I64,
    root: _F,
    rot: _F,
    before_root: _F,
    before_rot: _F,
    moving: NDArray[np.bool_],
    dt: float,
) -> None:
    """Put the bodies of ragdolls ``ordinals`` (ascending, in the layout) on poses: roots ``[n,3]``
    and their local rotations end to end ``[ΣJ,4]``. Those with ``moving [n]`` move as they moved
    from ``before_root``/``before_rot`` (same shapes) in ``dt`` (the target velocities of an animated
    placement); the others are at rest.

    One pass for every ragdoll joining at once: a fall pulls in a dozen, and placing them one by one
    was most of that step's Python. Each number is the same elementwise arithmetic as one at a time.
    """
    n = len(ordinals)
    if n == 0:
        return
    sizes = L.starts[ordinals + 1] - L.starts[ordinals]
    off = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.int64)
    which = np.full(L.num_ragdolls, -1, dtype=np.int64)  # layout ordinal -> its place in ``ordinals``
    which[ordinals] = np.arange(n)
    shift = np.zeros(L.num_ragdolls, dtype=np.int64)  # layout flat joint -> row of ``rot``
    shift[ordinals] = off - L.starts[ordinals]
    rq, rd = L.root_q[ordinals], L.root_d[ordinals]
    first = rot[off]
    d.qpos[rq[:, None] + np.arange(3)] = root
    d.qpos[rq[:, None] + np.arange(3, 7)] = first
    b = which[L.ball_owner] >= 0
    b_src = L.ball_src[b] + shift[L.ball_owner[b]]
    ball = rot[b_src]
    d.qpos[L.ball_q[b][:, None] + np.arange(4)] = ball
    h = which[L.hinge_owner] >= 0
    h_src = L.hinge_src[h] + shift[L.hinge_owner[h]]
    h_axis = L.hinge_axis[h]
    hinge = hinge_angles(rot[h_src], h_axis)
    d.qpos[L.hinge_q[h]] = hinge
    d.qvel[_ranges(L.dofs[ordinals, 0], L.dofs[ordinals, 1])] = 0.0
    if moving.any():
        k = np.nonzero(moving)[0]
        q0 = before_rot[off[k]]
        d.qvel[rd[k][:, None] + np.arange(3)] = (root[k] - before_root[k]) / dt
        d.qvel[rd[k][:, None] + np.arange(3, 6)] = (
            quat.rotate(q0, quat.log(quat.mul(quat.conjugate(q0), first[k]))) / dt
        )
        bm = moving[which[L.ball_owner[b]]]
        d.qvel[L.ball_d[b][bm][:, None] + np.arange(3)] = (
            quat.log(quat.mul(quat.conjugate(before_rot[b_src[bm]]), ball[bm])) / dt
        )
        hm = moving[which[L.hinge_owner[h]]]
        d.qvel[L.hinge_d[h][hm]] = (hinge[hm] - hinge_angles(before_rot[h_src[hm]], h_axis[hm])) / dt
    d.mocap_pos[L.pin_mocap[ordinals]] = root
    d.mocap_quat[L.pin_mocap[ordinals]] = first


def project_twist(L: Layout, d: mujoco.MjData) -> None:
    """Clamp each ball joint's twist about its bone to the profile's range (projection).

    MuJoCo limits a ball joint's total rotation angle (our swing cone); the twist range
    is enforced here once per step, removing the twist velocity that pushes outwards.
    """
    if len(L.ball_q) == 0:
        return
    if jit.enabled():
        twist_kernel(L.ball_q, L.ball_d, L.ball_axis, L.ball_twist, d.qpos, d.qvel)
        return
    qi = L.ball_q[:, None] + np.arange(4)
    di = L.ball_d[:, None] + np.arange(3)
    swing, twist = quat.swing_twist(quat.align_hemisphere(d.qpos[qi]), L.ball_axis)
    ang = 2.0 * np.arctan2(np.sum(twist[:, 1:] * L.ball_axis, axis=1), twist[:, 0])
    over = np.abs(ang) > L.ball_twist
    if not over.any():
        return
    clamped = quat.from_axis_angle(L.ball_axis, np.clip(ang, -L.ball_twist, L.ball_twist))
    d.qpos[qi[over]] = quat.normalize(quat.mul(swing, clamped))[over]
    w = d.qvel[di]
    rate = np.sum(w * L.ball_axis, axis=1)
    outward = over & (np.sign(rate) == np.sign(ang))
    d.qvel[di[outward]] = (w - rate[:, None] * L.ball_axis)[outward]


def read_poses(L: Layout, d: mujoco.MjData) -> tuple[_F, _F]:
    """Roots ``[P,3]`` and flat local rotations ``[ΣJ,4]`` of every ragdoll."""
    if jit.enabled():
        roots, rot = np.empty((L.num_ragdolls, 3)), np.empty((int(L.starts[-1]), 4))
        read_kernel(L.starts, L.root_q, L.ball_src, L.ball_q, L.hinge_src, L.hinge_q, L.hinge_axis, d.qpos, roots, rot)
        return roots, rot
    roots = d.qpos[L.root_q[:, None] + np.arange(3)]
    rot = quat.identity(int(L.starts[-1]))
    rot[L.starts[:-1]] = d.qpos[L.root_q[:, None] + np.arange(3, 7)]
    rot[L.ball_src] = d.qpos[L.ball_q[:, None] + np.arange(4)]
    rot[L.hinge_src] = quat.from_axis_angle(L.hinge_axis, d.qpos[L.hinge_q])
    return roots, quat.normalize(rot)
