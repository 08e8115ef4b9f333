"""Both hands on a sphere's surface (rolling a snowball), via two-bone IK on the arms.

The contacts are the two points of the sphere facing the character, one to each
side of its front (``spread``) and a little above its equator (``elevation``); the
palms turn to the surface normal, fingers running on along the arm's direction.
When the sphere is out of reach the spine leans towards it (up to ``max_lean``)
before the arms are solved, so a small snowball near the feet is reached by
bending, not by stretching the arms out of their sockets.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from engine import quat
from engine.ik._vec import cross, path_fk, rotate
from engine.ik.two_bone import two_bone_ik
from engine.pose import Pose
from engine.skeleton import Skeleton

__all__ = ["Arm", "HUMANOID_ARMS", "sphere_contacts", "hands_on_sphere"]

F = NDArray[np.float64]
_UP = np.array([0.0, 1.0, 0.0])


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


def _unit(v: F) -> F:
    return v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), 1e-12)


def _frame(a: F, b: F) -> F:
    """Rotation matrices whose columns are ``a``, ``b`` (orthogonalised) and ``a × b``."""
    a = _unit(a)
    b = _unit(b - np.sum(a * b, axis=-1, keepdims=True) * a)
    return np.stack([a, b, cross(a, b)], axis=-1)


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
    c = np.asarray(centre, dtype=np.float64)
    toward = np.asarray(facing_from, dtype=np.float64) - c
    toward[1] = 0.0
    lft = np.asarray(left, dtype=np.float64).copy()
    lft[1] = 0.0
    lft = _unit(lft)
    if np.linalg.norm(toward) < 1e-6:
        toward = cross(lft, _UP)  # standing on top: use the character's back direction
    toward = _unit(toward)
    sides = np.array([1.0, -1.0])[:, None]
    horiz = _unit(np.cos(spread) * toward[None] + np.sin(spread) * sides * lft[None])
    normals = np.cos(elevation) * horiz + np.sin(elevation) * _UP[None]
    return c[None] + radius * normals, normals


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
    centre = np.asarray(centre, dtype=np.float64)
    ids = [(skeleton.index(a.upper), skeleton.index(a.lower), skeleton.index(a.hand)) for a in arms]
    off = skeleton.offsets if offsets is None else np.asarray(offsets, dtype=np.float64)
    upper_len = np.array([np.linalg.norm(off[lo]) + np.linalg.norm(off[h]) for _, lo, h in ids])

    def targets() -> tuple[F, F, F, F]:
        wp, wr = path_fk(skeleton, pose.root, pose.rotations, ids[0][0], offsets)
        chest = wp[int(skeleton.parents[ids[0][0]])]
        body_rot = pose.rotations[0]
        left = rotate(body_rot, np.array([1.0, 0.0, 0.0]))
        contacts, normals = sphere_contacts(centre, radius, chest, left, spread=spread, elevation=elevation)
        fwd = rotate(body_rot, np.array([0.0, 0.0, 1.0]))
        shoulders = np.array([path_fk(skeleton, pose.root, pose.rotations, u, offsets)[0][u] for u, _, _ in ids])
        rots = []
        for arm, n, sh, ct in zip(arms, normals, shoulders, contacts, strict=True):
            along = ct - sh
            fingers = along - np.dot(along, n) * n
            if np.linalg.norm(fingers) < 1e-6:
                fingers = fwd - np.dot(fwd, n) * n
            world = _frame(-n, fingers)
            local = _frame(np.asarray(arm.palm_normal, dtype=np.float64), np.asarray(arm.fingers, dtype=np.float64))
            rots.append(quat.from_matrix(world @ local.T))
        hand_rot = np.array(rots)
        palms = np.array([a.palm for a in arms], dtype=np.float64)
        wrists = contacts - rotate(hand_rot, palms)
        return wrists, hand_rot, shoulders, fwd

    wrists, hand_rot, shoulders, fwd = targets()
    if lean_joint is not None:
        lj = skeleton.index(lean_joint)
        leaned = 0.0
        for _ in range(6):  # lean, then re-measure: the shoulders move on an arc
            short = np.max(np.linalg.norm(wrists - shoulders, axis=-1) - 0.97 * upper_len)
            if short <= 1e-4:
                break
            wp, wr = path_fk(skeleton, pose.root, pose.rotations, lj, offsets)
            torso = float(np.linalg.norm(shoulders.mean(axis=0) - wp[lj]))
            toward = centre - wp[lj]
            toward[1] = 0.0
            axis = cross(_UP, _unit(toward) if np.linalg.norm(toward) > 1e-6 else fwd)
            angle = min(short / max(torso, 1e-3), max_lean - leaned)
            if angle <= 1e-6:
                break
            leaned += angle
            p = int(skeleton.parents[lj])
            parent_rot = wr[p] if p >= 0 else quat.identity()
            turn = quat.from_axis_angle(axis, angle)
            world = quat.mul(turn, wr[lj])
            pose.rotations[lj] = quat.mul(quat.conjugate(parent_rot), world)
            wrists, hand_rot, shoulders, fwd = targets()
    reached = []
    for arm, (u, lo, h), tgt, hr, sh in zip(arms, ids, wrists, hand_rot, shoulders, strict=True):
        out = rotate(pose.rotations[0], np.array([arm.side, 0.0, 0.0]))
        pole = sh + 0.5 * out - 0.8 * fwd - 0.3 * _UP  # elbows bend back and out
        wrist = two_bone_ik(skeleton, pose, (u, lo, h), tgt, pole, end_rotation=hr, offsets=offsets)
        reached.append(wrist + rotate(hr, np.asarray(arm.palm, dtype=np.float64)))
    return np.array(reached)
