"""The two-bone solve of :mod:`engine.ik.two_bone` for one limb of one pose, on floats.

Same three steps, same formulas, same order of operations as the batched solver
(bend by the law of cosines, aim at the target, swivel to the pole), written on
tuples because a single limb is a few dozen 3-vector operations and numpy's
per-call cost would be 95% of the time. ``tests/engine/ik/test_two_bone.py``
checks this path against the batched one on random limbs.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from engine.ik._scalar import (
    Q_ID,
    Q,
    V,
    add,
    as_q,
    between,
    chain_fk,
    cross,
    dot,
    from_axis_angle,
    norm,
    qconj,
    qmul,
    qnormalize,
    qrot,
    slerp,
    sub,
    unit,
)

__all__ = ["solve_limb"]

_EPS = 1e-9
_X: V = (1.0, 0.0, 0.0)
_Z: V = (0.0, 0.0, 1.0)


def _div(a: float, b: float) -> float:
    """``a / b`` with numpy's answer for ``b == 0`` (±inf or NaN) instead of an exception."""
    if b != 0.0:
        return a / b
    return math.nan if a == 0.0 or math.isnan(a) else math.copysign(math.inf, a) * math.copysign(1.0, b)


def _angle(u: V, v: V) -> float:
    return math.acos(min(max(dot(unit(u, _EPS), unit(v, _EPS)), -1.0), 1.0))


def _about(point: V, centre: V, q: Q) -> V:
    return add(centre, qrot(q, sub(point, centre)))


def solve_limb(
    parents: NDArray[np.int64],
    root: V,
    rot: list[Sequence[float]],
    off: Sequence[Sequence[float]],
    joints: tuple[int, int, int],
    target: V,
    pole: V | None,
    end_rotation: Q | None,
    weight: float = 1.0,
) -> V:
    """Solve limb ``joints = (a, b, c)`` of one pose; writes the three local rotations into ``rot``.

    ``rot``/``off`` are the pose's local rotations and offsets as lists of tuples;
    ``end_rotation`` must already be a unit quaternion. Returns where ``c`` is now.
    """
    if not (math.isfinite(target[0]) and math.isfinite(target[1]) and math.isfinite(target[2])):
        raise ValueError("two_bone_ik target must be finite")
    ia, ib, ic = joints
    wpos, wrot = chain_fk(parents, root, rot, off, ic)
    a, b, c = wpos[ia], wpos[ib], wpos[ic]
    qa, qb, qc = wrot[ia], wrot[ib], wrot[ic]
    pa = int(parents[ia])
    qpa = wrot[pa] if pa >= 0 else Q_ID

    lab = norm(sub(b, a))
    lcb = norm(sub(c, b))
    lat = min(max(norm(sub(target, a)), abs(lab - lcb) + 1e-6), lab + lcb - 1e-6)

    # 1. bend in the limb's plane (from the pole, or a perpendicular, where it is straight).
    ca, ba = sub(c, a), sub(b, a)
    normal = cross(ca, ba)
    if norm(normal) < 1e-6 * max(lab * lcb, _EPS):
        hint = sub(pole, a) if pole is not None else cross(ca, _X)
        fallback = cross(ca, hint)
        if norm(fallback) < 1e-9:
            fallback = cross(ca, _Z)
        normal = fallback
    axis0 = unit(normal, _EPS)
    ac_ab_0 = _angle(ca, ba)
    ba_bc_0 = _angle(sub(a, b), sub(c, b))
    ac_ab_1 = math.acos(min(max(_div(lcb * lcb - lab * lab - lat * lat, -2.0 * lab * lat), -1.0), 1.0))
    ba_bc_1 = math.acos(min(max(_div(lat * lat - lab * lab - lcb * lcb, -2.0 * lab * lcb), -1.0), 1.0))
    rb = from_axis_angle(axis0, ba_bc_1 - ba_bc_0)
    c = _about(c, b, rb)
    ra = from_axis_angle(axis0, ac_ab_1 - ac_ab_0)
    b, c = _about(b, a, ra), _about(c, a, ra)

    # 2. aim a → c at the target.
    r1 = between(sub(c, a), sub(target, a))
    b, c = _about(b, a, r1), _about(c, a, r1)
    root_turn = qmul(r1, ra)

    # 3. swivel about a → t so that b faces the pole.
    if pole is not None:
        d = unit(sub(c, a), _EPS)
        pole_dir = sub(pole, a)
        ba = sub(b, a)
        s = dot(ba, d)
        u = (ba[0] - s * d[0], ba[1] - s * d[1], ba[2] - s * d[2])
        s = dot(pole_dir, d)
        v = (pole_dir[0] - s * d[0], pole_dir[1] - s * d[1], pole_dir[2] - s * d[2])
        ang = 0.0
        if norm(u) > 1e-9 and norm(v) > 1e-9:
            uu, vv = unit(u, _EPS), unit(v, _EPS)
            ang = math.atan2(dot(cross(uu, vv), d), dot(uu, vv))
        r2 = from_axis_angle(d, ang)
        b, c = _about(b, a, r2), _about(c, a, r2)
        root_turn = qmul(r2, root_turn)

    new_qa = qmul(root_turn, qa)
    new_qb = qmul(root_turn, qmul(rb, qb))
    new_qc = qmul(new_qb, qmul(qconj(qb), qc)) if end_rotation is None else end_rotation
    for j, q in ((ia, qmul(qconj(qpa), new_qa)), (ib, qmul(qconj(new_qa), new_qb)), (ic, qmul(qconj(new_qb), new_qc))):
        rot[j] = qnormalize(q) if weight >= 1.0 else slerp(as_q(rot[j]), q, weight)
    return c
