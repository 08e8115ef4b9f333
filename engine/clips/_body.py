"""Assemble a clip from per-frame body intent: pelvis, spine, arms as angles; legs as ankle targets.

Every authoring module (gaits, stances, get-up, jump) describes a motion with the same
:class:`BodyIntent` arrays; this module is the one place that turns intent into joint
rotations. Legs go through the analytic leg IK so feet land exactly where the intent puts
them. Travel is separated into root motion here too: the ``travel`` track (a smooth
ground-plane path, no sway, no heading wobble) becomes the clip's root motion through
:meth:`Clip.extract_root_motion`, and whatever the pelvis does around it (sway, bob,
yaw) stays in the in-place clip. Extracting the raw pelvis instead would push its ±5°
walking yaw into the root heading, making the character's facing wobble and a loop drift.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from engine import quat
from engine.arrays import F64 as F
from engine.clip import Clip
from engine.clips._legik import LegSolution, solve_leg
from engine.skeleton import Skeleton

__all__ = ["BodyIntent", "assemble", "upper_body_rotations", "foot_rotation", "pelvis_rotation", "SIDES"]

SIDES = ("l", "r")
_X = np.array([1.0, 0.0, 0.0])
_Y = np.array([0.0, 1.0, 0.0])
_Z = np.array([0.0, 0.0, 1.0])


@dataclass
class BodyIntent:
    """What the body does per frame (``N`` frames). Angles are degrees.

    Attributes:
        pelvis_pos: ``[N,3]`` world position of the hips joint.
        pelvis_ypr: ``[N,3]`` pelvis yaw (about +Y), pitch (forward lean +), roll (left side up +).
        spine_ypr, chest_ypr, neck_ypr, head_ypr: ``[N,3]`` local yaw/pitch/roll of the column.
        arms: ``[N,2,3]`` per side (left, right): shoulder flexion (arm forward +), abduction
            (arm out +), elbow flexion (forearm forward +).
        ankle: ``[N,2,3]`` world ankle targets per side.
        foot_pitch: ``[N,2]`` toe-up pitch of each foot (negative: heel up / toes pointed).
        foot_yaw: ``[N,2]`` toe-out of each foot (outward +).
        travel: ``[N,3]`` smooth ground-plane path that becomes root motion, or ``None``.
        hand_flex: ``[N,2]`` wrist flexion (palm forward +).
    """

    pelvis_pos: F
    pelvis_ypr: F
    spine_ypr: F
    chest_ypr: F
    neck_ypr: F
    head_ypr: F
    arms: F
    ankle: F
    foot_pitch: F
    foot_yaw: F
    travel: F | None = None
    hand_flex: F | None = None


def _ypr(a: F) -> F:
    return quat.from_euler("yxz", a, degrees=True)


def pelvis_rotation(ypr: F) -> F:
    """World rotation of the pelvis from yaw/pitch/roll degrees ``[...,3]``."""
    return _ypr(ypr)


def foot_rotation(pitch: F, yaw: F, side: int) -> F:
    """World rotation of a foot: toe-out ``yaw`` (outward +) then toe-up ``pitch``, degrees."""
    sign = 1.0 if side == 0 else -1.0
    return quat.mul(
        quat.from_axis_angle(_Y, np.radians(sign * np.asarray(yaw))),
        quat.from_axis_angle(_X, -np.radians(np.asarray(pitch))),
    )


def _mirror(ypr: F, side: int) -> F:
    """Yaw and roll change sign on the right side of the body."""
    if side == 0:
        return ypr
    return ypr * np.array([-1.0, 1.0, -1.0])


def upper_body_rotations(skeleton: Skeleton, intent: BodyIntent) -> F:
    """Local rotations ``[N,J,4]`` of the pelvis, column and arms; legs left at identity.

    Split from :func:`assemble` so checks on the upper body (hands above the floor) can run
    forward kinematics without solving the legs.
    """
    n = len(intent.pelvis_pos)
    j = skeleton.index
    rot = np.tile(quat.IDENTITY, (n, skeleton.num_joints, 1))
    rot[:, 0] = pelvis_rotation(intent.pelvis_ypr)
    rot[:, j("spine")] = _ypr(intent.spine_ypr)
    rot[:, j("chest")] = _ypr(intent.chest_ypr)
    rot[:, j("neck")] = _ypr(intent.neck_ypr)
    rot[:, j("head")] = _ypr(intent.head_ypr)
    hand = np.zeros((n, 2)) if intent.hand_flex is None else intent.hand_flex
    for s, side in enumerate(SIDES):
        sign = 1.0 if s == 0 else -1.0
        fwd, abd, elbow = (intent.arms[:, s, k] for k in range(3))
        # Abduct first, then flex about the chest's X: a raised arm keeps its outward spread
        # (the other order would swing an overhead arm inwards, across the head).
        rot[:, j(f"{side}_upper_arm")] = quat.mul(
            quat.from_axis_angle(_X, -np.radians(fwd)), quat.from_axis_angle(_Z, np.radians(sign * abd))
        )
        rot[:, j(f"{side}_lower_arm")] = quat.from_axis_angle(_X, -np.radians(elbow))
        rot[:, j(f"{side}_hand")] = quat.from_axis_angle(_X, -np.radians(hand[:, s]))
    return rot


def assemble(
    skeleton: Skeleton,
    intent: BodyIntent,
    name: str,
    fps: float,
    loop: bool,
    markers: dict[str, float] | None = None,
) -> tuple[Clip, tuple[LegSolution, LegSolution]]:
    """Turn ``intent`` into a :class:`Clip`, with root motion from ``intent.travel``.

    Returns the clip and the two leg solutions (their ``reach`` tells the author whether any
    ankle target was out of reach, which would make the foot slide).
    """
    n = len(intent.pelvis_pos)
    j = skeleton.index
    rot = upper_body_rotations(skeleton, intent)
    pelvis = rot[:, 0]
    legs = []
    for s, side in enumerate(SIDES):
        sign = 1.0 if s == 0 else -1.0
        up, lo, ft = j(f"{side}_upper_leg"), j(f"{side}_lower_leg"), j(f"{side}_foot")
        hip = intent.pelvis_pos + quat.rotate(pelvis, skeleton.offsets[up])
        toe_out = quat.from_axis_angle(_Y, np.radians(sign * intent.foot_yaw[:, s]))
        pole = quat.rotate(quat.mul(pelvis, toe_out), _Z)
        leg = solve_leg(
            hip,
            pelvis,
            intent.ankle[:, s],
            pole,
            foot_rotation(intent.foot_pitch[:, s], intent.foot_yaw[:, s], s),
            float(np.linalg.norm(skeleton.offsets[lo])),
            float(np.linalg.norm(skeleton.offsets[ft])),
        )
        rot[:, up], rot[:, lo], rot[:, ft] = leg.upper, leg.knee, leg.foot
        legs.append(leg)
    travel = np.zeros((n, 3)) if intent.travel is None else np.asarray(intent.travel, dtype=np.float64)
    travel = (travel - travel[0]) * np.array([1.0, 0.0, 1.0])
    carrier = Clip(
        name,
        skeleton,
        fps,
        travel + np.array([0.0, 1.0, 0.0]),
        np.tile(quat.IDENTITY, (n, skeleton.num_joints, 1)),
        loop,
    )
    root_motion = carrier.extract_root_motion().root_motion
    root = intent.pelvis_pos - travel
    clip = Clip(name, skeleton, fps, root, rot, loop, markers=dict(markers or {}))
    if intent.travel is not None:
        clip = replace(clip, root_motion=root_motion)
    return clip, (legs[0], legs[1])
