"""Both hands on a sphere's surface (rolling a snowball), via two-bone IK on the arms.

The contacts are the two points of the sphere facing the character, one to each
side of its front (``spread``) and a little above its equator (``elevation``); the
palms turn to the surface normal, fingers running on along the arm's direction.
When the sphere is out of reach the spine leans towards it (up to ``max_lean``)
before the arms are solved, so a small snowball near the feet is reached by
bending, not by stretching the arms out of their sockets.

One puppet's arms, re-measured after each lean, are a few hundred 3-vector
operations: they run on floats (:mod:`engine.ik._scalar`, :mod:`engine.ik._limb`),
since numpy's per-call cost made this stage 10 ms per puppet.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from engine.ik._limb import solve_limb
from engine.ik._scalar import (
    Q_ID,
    Q,
    V,
    add,
    chain_fk,
    cross,
    dot,
    from_axis_angle,
    from_frames,
    norm,
    qconj,
    qmul,
    qnormalize,
    qrot,
    scale,
    sub,
    unit,
)
from engine.pose import Pose
from engine.skeleton import Skeleton

__all__ = ["Arm", "HUMANOID_ARMS", "sphere_contacts", "hands_on_sphere"]

from engine.arrays import F64 as F

_UP: V = (0.0, 1.0, 0.0)


@dataclass(frozen=True)
class Arm:
    """An arm's joints, its side (+1 left, −1 right), and its palm in the hand's frame.

    ``palm`` is the point of the palm's surface, ``palm_normal`` the way the palm
    faces and ``fingers`` the way the fingers point, all in the hand's local frame.
    """

    upper: str
    lower: str
    hand: str
    side: float
    palm: tuple[float, float, float]
    palm_normal: tuple[float, float, float]
    fingers: tuple[float, float, float] = (0.0, -1.0, 0.0)


# At rest the humanoid's palms face its thighs: the left palm looks along −X, the right along +X.
HUMANOID_ARMS: tuple[Arm, ...] = (
    Arm("l_upper_arm", "l_lower_arm", "l_hand", 1.0, (-0.02, -0.045, 0.0), (-1.0, 0.0, 0.0)),
    Arm("r_upper_arm", "r_lower_arm", "r_hand", -1.0, (0.02, -0.045, 0.0), (1.0, 0.0, 0.0)),
)


def _contacts(
    centre: V, radius: float, facing_from: V, left: V, spread: float, elevation: float
) -> tuple[list[V], list[V]]:
    """:func:`sphere_contacts` on floats: contact points and normals, left then right."""
    toward = (facing_from[0] - centre[0], 0.0, facing_from[2] - centre[2])
    lft = unit((left[0], 0.0, left[2]), 1e-12)
    if norm(toward) < 1e-6:
        toward = cross(lft, _UP)  # standing on top: use the character's back direction
    toward = unit(toward, 1e-12)
    cs, sn = math.cos(spread), math.sin(spread)
    ce, se = math.cos(elevation), math.sin(elevation)
    points, normals = [], []
    for side in (1.0, -1.0):
        k = sn * side
        horiz = unit(add(scale(cs, toward), scale(k, lft)), 1e-12)
        n = add(scale(ce, horiz), scale(se, _UP))
        normals.append(n)
        points.append(add(centre, scale(radius, n)))
    return points, normals


def _vec3(v: ArrayLike) -> V:
    x, y, z = np.asarray(v, dtype=np.float64).reshape(3).tolist()
    return (x, y, z)


def sphere_contacts(
    centre: ArrayLike,
    radius: float,
    facing_from: ArrayLike,
    left: ArrayLike,
    *,
    spread: float = 0.7,
    elevation: float = 0.35,
) -> tuple[F, F]:
    """Contact points ``[2,3]`` (left, right) and outward normals ``[2,3]`` on the sphere.

    ``facing_from`` is a point of the character (its chest); ``left`` its left direction.
    """
    points, normals = _contacts(_vec3(centre), float(radius), _vec3(facing_from), _vec3(left), spread, elevation)
    return np.array(points), np.array(normals)


def hands_on_sphere(
    skeleton: Skeleton,
    pose: Pose,
    centre: ArrayLike,
    radius: float,
    arms: tuple[Arm, ...] = HUMANOID_ARMS,
    *,
    lean_joint: str | None = "spine",
    max_lean: float = 0.9,
    spread: float = 0.7,
    elevation: float = 0.35,
    offsets: ArrayLike | None = None,
) -> F:
    """Put one puppet's palms on the sphere in place; returns the palm points ``[2,3]`` reached."""
    if radius <= 0 or not np.all(np.isfinite(centre)):
        raise ValueError("sphere needs a finite centre and a positive radius")
    if len(arms) != 2:
        raise ValueError("hands_on_sphere places exactly two arms (left, right)")
    cen = _vec3(centre)
    ids = [(skeleton.index(a.upper), skeleton.index(a.lower), skeleton.index(a.hand)) for a in arms]
    par = skeleton.parents
    off = (skeleton.offsets if offsets is None else np.asarray(offsets, dtype=np.float64)).tolist()
    upper_len = [norm(off[lo]) + norm(off[h]) for _, lo, h in ids]
    root = tuple(pose.root.tolist())
    rot = pose.rotations.tolist()

    def targets() -> tuple[list[V], list[Q], list[V], V]:
        """Wrist targets, hand rotations, shoulders and the body's forward, from the current pose."""
        arm_fk = [chain_fk(par, root, rot, off, u)[0] for u, _, _ in ids]
        chest = arm_fk[0][int(par[ids[0][0]])]
        shoulders = [wp[u] for wp, (u, _, _) in zip(arm_fk, ids, strict=True)]
        left, fwd = qrot(rot[0], (1.0, 0.0, 0.0)), qrot(rot[0], (0.0, 0.0, 1.0))
        contacts, normals = _contacts(cen, radius, chest, left, spread, elevation)
        wrists, hand_rot = [], []
        for arm, n, sh, ct in zip(arms, normals, shoulders, contacts, strict=True):
            along = sub(ct, sh)
            fingers = sub(along, scale(dot(along, n), n))
            if norm(fingers) < 1e-6:
                fingers = sub(fwd, scale(dot(fwd, n), n))
            hr = from_frames(((-n[0], -n[1], -n[2]), fingers), (arm.palm_normal, arm.fingers))
            hand_rot.append(hr)
            wrists.append(sub(ct, qrot(hr, arm.palm)))
        return wrists, hand_rot, shoulders, fwd

    wrists, hand_rot, shoulders, fwd = targets()
    if lean_joint is not None:
        lj = skeleton.index(lean_joint)
        leaned = 0.0
        for _ in range(6):  # lean, then re-measure: the shoulders move on an arc
            short = max(norm(sub(w, s)) - 0.97 * ln for w, s, ln in zip(wrists, shoulders, upper_len, strict=True))
            if short <= 1e-4:
                break
            wp, wr = chain_fk(par, root, rot, off, lj)
            mid = ((shoulders[0][0] + shoulders[1][0]) / 2, (shoulders[0][1] + shoulders[1][1]) / 2,
                   (shoulders[0][2] + shoulders[1][2]) / 2)  # fmt: skip
            torso = norm(sub(mid, wp[lj]))
            toward = (cen[0] - wp[lj][0], 0.0, cen[2] - wp[lj][2])
            axis = cross(_UP, unit(toward, 1e-12) if norm(toward) > 1e-6 else fwd)
            angle = min(short / max(torso, 1e-3), max_lean - leaned)
            if angle <= 1e-6:
                break
            leaned += angle
            p = int(par[lj])
            parent_rot = wr[p] if p >= 0 else Q_ID
            rot[lj] = qmul(qconj(parent_rot), qmul(from_axis_angle(axis, angle), wr[lj]))
            pose.rotations[lj] = rot[lj]
            wrists, hand_rot, shoulders, fwd = targets()
    reached = []
    for arm, (u, lo, h), tgt, hr, sh in zip(arms, ids, wrists, hand_rot, shoulders, strict=True):
        out = qrot(rot[0], (arm.side, 0.0, 0.0))
        pole = sub(sub(add(sh, scale(0.5, out)), scale(0.8, fwd)), scale(0.3, _UP))  # elbows bend back and out
        wrist = solve_limb(par, root, rot, off, (u, lo, h), tgt, pole, qnormalize(hr))
        for j in (u, lo, h):
            pose.rotations[j] = rot[j]
        reached.append(add(wrist, qrot(hr, arm.palm)))
    return np.array(reached)
