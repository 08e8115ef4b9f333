"""Analytic two-bone IK (legs and arms), batched over puppets, for per-frame use.

Given a limb ``a → b → c`` (hip, knee, ankle or shoulder, elbow, wrist), a target
``t`` for ``c`` and a pole point ``p`` that the middle joint should face, the law of
cosines gives the two interior angles that put ``|c − a|`` at ``|t − a|``; three
rotations then finish the job:

1. bend: turn ``b`` and ``a`` about the limb's plane normal so the triangle has
   the wanted angles (where the limb is straight the plane comes from the pole);
2. aim: turn ``a`` so ``a → c`` points at the target;
3. swivel: turn ``a`` about ``a → t`` so ``b`` lies on the pole's side.

Each is a world rotation applied at a joint, so positions are updated analytically
and forward kinematics runs once. Targets out of reach stretch the limb straight
towards them; targets closer than ``|ab − bc|`` fold it as far as it goes. The
pose is changed in place, like the engine's other pose systems.

One pose (the per-frame case) goes to the float version in :mod:`engine.ik._limb`,
which is some thirty times cheaper than numpy on a single limb and agrees with the
batched code below to rounding.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from engine import quat
from engine.ik._limb import solve_limb
from engine.ik._vec import cross, path_fk, rotate
from engine.pose import Pose
from engine.skeleton import Skeleton

__all__ = ["two_bone_ik"]

from engine.arrays import F64 as F

_EPS = 1e-9


def _unit(v: F) -> F:
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.maximum(n, _EPS)


def _angle(u: F, v: F) -> F:
    return np.arccos(np.clip(np.sum(_unit(u) * _unit(v), axis=-1), -1.0, 1.0))


def _rotate_about(point: F, centre: F, q: F) -> F:
    return centre + rotate(q, point - centre)


def _single(value: ArrayLike | None, size: int) -> bool:
    return value is None or np.shape(value) == (size,)


def _two_bone_one(
    skeleton: Skeleton,
    pose: Pose,
    joints: tuple[int, int, int],
    target: F,
    pole: ArrayLike | None,
    end_rotation: ArrayLike | None,
    offsets: ArrayLike | None,
    weight: float,
) -> F:
    """One pose, one limb: solve on floats and write the three joints back."""
    off = skeleton.offsets if offsets is None else np.asarray(offsets, dtype=np.float64)
    rot = pose.rotations.tolist()
    end = None if end_rotation is None else tuple(quat.normalize(end_rotation).tolist())
    pole_v = None if pole is None else tuple(np.asarray(pole, dtype=np.float64).tolist())
    root = tuple(np.asarray(pose.root, dtype=np.float64).tolist())
    c = solve_limb(skeleton.parents, root, rot, off.tolist(), joints, tuple(target.tolist()), pole_v, end, weight)
    for j in joints:
        pose.rotations[j] = rot[j]
    return np.array(c)


def two_bone_ik(
    skeleton: Skeleton,
    pose: Pose,
    joints: tuple[int | str, int | str, int | str],
    target: ArrayLike,
    pole: ArrayLike | None = None,
    *,
    end_rotation: ArrayLike | None = None,
    offsets: ArrayLike | None = None,
    weight: ArrayLike = 1.0,
) -> F:
    """Solve one limb of every puppet in ``pose`` (shape ``[...,J,4]``) in place.

    Args:
        skeleton: the hierarchy; ``joints`` = (root, mid, end) of the limb, each the
            parent of the next.
        pose: the pose to change (leading axes are puppets).
        target: ``[...,3]`` world target for the end joint.
        pole: ``[...,3]`` world point the middle joint should point towards; ``None``
            keeps the limb's current bend plane.
        end_rotation: ``[...,4]`` world rotation for the end joint (a foot flat on the
            ground, a palm on a ball); ``None`` keeps its local rotation.
        offsets: per-puppet bone offsets.
        weight: ``[...]`` 0..1 blend from the input pose to the solved one.

    Returns:
        ``[...,3]`` where the end joint is now (the target, or as close as the limb reaches).
    """
    ia, ib, ic = (j if isinstance(j, int) else skeleton.index(j) for j in joints)
    if skeleton.parents[ib] != ia or skeleton.parents[ic] != ib:
        names = " → ".join(skeleton.names[j] for j in (ia, ib, ic))
        raise ValueError(f"{names} is not a parent chain")
    target = np.asarray(target, dtype=np.float64)
    if not np.all(np.isfinite(target)):
        raise ValueError("two_bone_ik target must be finite")
    rot = pose.rotations
    one = rot.ndim == 2 and target.shape == (3,) and np.ndim(weight) == 0 and (offsets is None or np.ndim(offsets) == 2)
    if one and _single(pole, 3) and _single(end_rotation, 4):
        return _two_bone_one(
            skeleton, pose, (ia, ib, ic), target, pole, end_rotation, offsets, float(np.asarray(weight))
        )
    wpos, wrot = path_fk(skeleton, pose.root, rot, ic, offsets)
    a, b, c = wpos[ia], wpos[ib], wpos[ic]
    qa, qb, qc = wrot[ia], wrot[ib], wrot[ic]
    pa = int(skeleton.parents[ia])
    qpa = wrot[pa] if pa >= 0 else quat.identity(*rot.shape[:-2])
    target = np.broadcast_to(target, a.shape)

    lab = np.linalg.norm(b - a, axis=-1)
    lcb = np.linalg.norm(c - b, axis=-1)
    lat = np.clip(np.linalg.norm(target - a, axis=-1), np.abs(lab - lcb) + 1e-6, lab + lcb - 1e-6)

    # 1. bend in the limb's plane (from the pole, or a perpendicular, where it is straight).
    normal = cross(c - a, b - a)
    straight = np.linalg.norm(normal, axis=-1) < 1e-6 * np.maximum(lab * lcb, _EPS)
    hint = (np.asarray(pole, dtype=np.float64) - a) if pole is not None else cross(c - a, [1.0, 0.0, 0.0])
    fallback = cross(c - a, hint)
    weak = np.linalg.norm(fallback, axis=-1) < 1e-9
    fallback = np.where(weak[..., None], cross(c - a, [0.0, 0.0, 1.0]), fallback)
    axis0 = _unit(np.where(straight[..., None], fallback, normal))
    ac_ab_0 = _angle(c - a, b - a)
    ba_bc_0 = _angle(a - b, c - b)
    ac_ab_1 = np.arccos(np.clip((lcb**2 - lab**2 - lat**2) / (-2.0 * lab * lat), -1.0, 1.0))
    ba_bc_1 = np.arccos(np.clip((lat**2 - lab**2 - lcb**2) / (-2.0 * lab * lcb), -1.0, 1.0))
    rb = quat.from_axis_angle(axis0, ba_bc_1 - ba_bc_0)
    c = _rotate_about(c, b, rb)
    ra = quat.from_axis_angle(axis0, ac_ab_1 - ac_ab_0)
    b, c = _rotate_about(b, a, ra), _rotate_about(c, a, ra)

    # 2. aim a → c at the target.
    r1 = quat.between(c - a, target - a)
    b, c = _rotate_about(b, a, r1), _rotate_about(c, a, r1)
    root_turn = quat.mul(r1, ra)

    # 3. swivel about a → t so that b faces the pole.
    if pole is not None:
        d = _unit(c - a)
        pole_dir = np.asarray(pole, dtype=np.float64) - a
        u = b - a - np.sum((b - a) * d, axis=-1, keepdims=True) * d
        v = pole_dir - np.sum(pole_dir * d, axis=-1, keepdims=True) * d
        ok = (np.linalg.norm(u, axis=-1) > 1e-9) & (np.linalg.norm(v, axis=-1) > 1e-9)
        ang = np.arctan2(np.sum(cross(_unit(u), _unit(v)) * d, axis=-1), np.sum(_unit(u) * _unit(v), axis=-1))
        r2 = quat.from_axis_angle(d, np.where(ok, ang, 0.0))
        b, c = _rotate_about(b, a, r2), _rotate_about(c, a, r2)
        root_turn = quat.mul(r2, root_turn)

    new_qa = quat.mul(root_turn, qa)
    new_qb = quat.mul(root_turn, quat.mul(rb, qb))
    new_qc = (quat.mul(new_qb, quat.mul(quat.conjugate(qb), qc)) if end_rotation is None
              else np.broadcast_to(quat.normalize(end_rotation), qc.shape))  # fmt: skip
    la = quat.mul(quat.conjugate(qpa), new_qa)
    lb = quat.mul(quat.conjugate(new_qa), new_qb)
    lc = quat.mul(quat.conjugate(new_qb), new_qc)
    w = np.asarray(weight, dtype=np.float64)
    full = w.ndim == 0 and float(w) >= 1.0
    for j, q in ((ia, la), (ib, lb), (ic, lc)):
        rot[..., j, :] = quat.normalize(q) if full else quat.slerp(rot[..., j, :], q, w)
    return c
