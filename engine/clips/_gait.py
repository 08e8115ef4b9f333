"""Locomotion cycles from gait intent: foot plants, heel-toe roll, swing keys, pelvis and arm keys.

A gait is described the way an animator would block it: where the foot plants relative to
the pelvis, when the heel lands, when it lifts and when the toe leaves; a few swing keys
(how high and where the ankle passes); the pelvis bob, sway and rotations; the arm swing.
Phase 0 is the left heel strike and 0.5 the right one (the sync-group convention), the
right side mirrors the left half a cycle later.

Stance is solved exactly: during heel strike the foot rolls about its heel, flat it is
still, during push-off it rolls about its toe tip, so the contact point never moves. The
swing is a clamped cubic through the swing keys whose end slopes equal the stance motion's,
so the foot leaves and lands without a jerk.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import CubicSpline

from engine import quat
from engine.arrays import F64 as F
from engine.clip import Clip
from engine.clips import _keys
from engine.clips._body import BodyIntent, assemble, foot_rotation, pelvis_rotation
from engine.clips._keys import Keys
from engine.clips._reach import lower_to_reach
from engine.clips.contacts import HEEL_OFFSET
from engine.skeleton import Skeleton

__all__ = ["FootPlan", "GaitSpec", "build_gait", "ANKLE_HEIGHT", "mirrored", "column_intent"]

ANKLE_HEIGHT = 0.06
"""Ankle height of a flat foot: the rest pose's, where the sole (heel and toe tip) is 1 cm up."""


@dataclass(frozen=True)
class FootPlan:
    """One foot's stepping, in fractions of the cycle from its own heel strike.

    Attributes:
        width: ankle distance from the walking line (metres).
        toe_out: outward yaw of the foot (degrees).
        front: how far ahead of the pelvis the flat-foot ankle plants at heel strike.
        strike_pitch: toe-up angle at heel strike (degrees).
        toeoff_pitch: heel-up angle at toe-off (degrees, positive).
        flat_at: phase the foot is flat (end of the heel roll).
        heel_off: phase the heel starts to rise.
        duty: phase of toe-off (the fraction of the cycle in stance).
        swing: keys ``(s, z ahead of pelvis, ankle height, toe-up pitch)`` with ``s`` the
            fraction of the swing (0 = toe-off, 1 = next heel strike).
        lift: how high the toe tip rises (and the heel hovers) at the lift-off and landing
            keys, which sit ``lift_s`` of the swing after toe-off and before heel strike.
            They make the toe leave the floor upwards and the heel come down onto its mark
            instead of skimming along the floor (which reads as a scuff or a slide).
    """

    width: float
    toe_out: float
    front: float
    strike_pitch: float
    toeoff_pitch: float
    flat_at: float
    heel_off: float
    duty: float
    swing: tuple[tuple[float, float, float, float], ...]
    lift: float = 0.02
    lift_s: float = 0.07

    def __post_init__(self) -> None:
        if not 0.0 < self.flat_at <= self.heel_off < self.duty < 1.0:
            raise ValueError("foot plan needs 0 < flat_at <= heel_off < duty < 1")
        s = [k[0] for k in self.swing]
        if any(not self.lift_s < a < 1.0 - self.lift_s for a in s) or any(np.diff(s) <= 0):
            raise ValueError(f"swing keys need increasing s strictly between {self.lift_s} and {1 - self.lift_s}")


@dataclass(frozen=True)
class GaitSpec:
    """A locomotion cycle's intent. Keys are ``(phase, value)``; angles in degrees.

    ``pelvis_ypr``/``spine_ypr``/``chest_ypr`` are yaw, pitch, roll; ``arm`` keys the left
    arm's (flexion, abduction, elbow) and the right arm plays them half a cycle later;
    ``gaze`` keys the head's pitch relative to level (the neck and head otherwise cancel the
    trunk's rotation so the eyes stay level, as people's do).
    """

    name: str
    speed: float
    period: float
    foot: FootPlan
    pelvis_height: Keys
    pelvis_sway: Keys
    pelvis_ypr: Keys
    spine_ypr: Keys
    chest_ypr: Keys
    arm: Keys
    gaze: Keys = ((0.0, 0.0),)
    hand_flex: float = 8.0
    fps: float = 60.0
    max_reach: float = 0.997
    markers: dict[str, float] = field(default_factory=lambda: {"left_down": 0.0, "right_down": 0.5})

    @property
    def frames(self) -> int:
        """Frames per cycle; even, so the right heel strike (phase 0.5) lands on a frame."""
        n = self.period * self.fps
        if abs(n - round(n)) > 1e-9 or round(n) % 2:
            raise ValueError(f"{self.name}: period × fps must be an even whole number of frames, got {n}")
        return int(round(n))


def mirrored(keys: Keys, flip: tuple[float, ...]) -> tuple[tuple[float, tuple[float, ...]], ...]:
    """Keys for a whole cycle from keys for its first half: the second half repeats them half
    a cycle later with each value multiplied by ``flip`` (−1 for sway, yaw and roll)."""
    out = []
    for p, v in keys:
        vals = tuple(np.atleast_1d(np.asarray(v, dtype=np.float64)).tolist())
        out.append((float(p), vals))
        out.append((float(p) + 0.5, tuple(a * b for a, b in zip(vals, flip, strict=True))))
    return tuple(sorted(out))


def _stance(plan: FootPlan, psi: F, side: int, toe: F) -> tuple[F, F]:
    """Ankle ``[N,3]`` (own frame: pelvis at strike is z = 0) and toe-up pitch ``[N]`` in stance."""
    sign = 1.0 if side == 0 else -1.0
    flat = np.array([sign * plan.width, ANKLE_HEIGHT, plan.front])
    s_roll = np.clip(psi / plan.flat_at, 0.0, 1.0)
    s_push = np.clip((psi - plan.heel_off) / (plan.duty - plan.heel_off), 0.0, 1.0)
    pitch = np.where(psi < plan.flat_at, plan.strike_pitch * (1.0 - s_roll) ** 2, 0.0)
    pitch = np.where(psi > plan.heel_off, -plan.toeoff_pitch * s_push**2, pitch)
    rot = foot_rotation(pitch, np.full_like(psi, plan.toe_out), side)
    rest = foot_rotation(np.zeros_like(psi), np.full_like(psi, plan.toe_out), side)
    pivot = np.where((psi < plan.flat_at)[:, None], HEEL_OFFSET, toe)
    ankle = flat + quat.rotate(rest, pivot) - quat.rotate(rot, pivot)
    return ankle, pitch


def _pivot_key(plan: FootPlan, side: int, pivot: F, lift: F, pitch: float) -> F:
    """Ankle and pitch ``[4]`` that put the foot's ``pivot`` point at ``lift`` from its ground mark."""
    rest = foot_rotation(np.zeros(1), np.full(1, plan.toe_out), side)[0]
    rot = foot_rotation(np.full(1, pitch), np.full(1, plan.toe_out), side)[0]
    mark = quat.rotate(rest, pivot)
    return np.append(mark + lift - quat.rotate(rot, pivot), pitch)


def foot_track(plan: FootPlan, stride: float, phase: F, side: int, toe: F) -> tuple[F, F]:
    """World ankle ``[N,3]`` and pitch ``[N]`` of one foot over cycle ``phase`` (pelvis nominal z = stride·phase).

    ``toe`` is the toe tip in the foot joint's frame (the skeleton's foot tip).
    """
    psi = np.mod(phase - (0.0 if side == 0 else 0.5), 1.0)
    sign = 1.0 if side == 0 else -1.0
    ankle = np.empty((len(psi), 3))
    pitch = np.empty(len(psi))
    st = psi <= plan.duty
    ankle[st], pitch[st] = _stance(plan, psi[st], side, toe)
    h = 1e-6
    a0, p0 = _stance(plan, np.array([plan.duty - h, plan.duty]), side, toe)
    a1, p1 = _stance(plan, np.array([0.0, h]), side, toe)
    a1 = a1 + np.array([0.0, 0.0, stride])
    flat = np.array([sign * plan.width, ANKLE_HEIGHT, plan.front])
    lift_off = _pivot_key(plan, side, toe, np.array([0.0, plan.lift, 0.005]), -plan.toeoff_pitch - 8.0)
    landing = _pivot_key(plan, side, HEEL_OFFSET, np.array([0.0, plan.lift, -0.01]), plan.strike_pitch + 4.0)
    swing_span = 1.0 - plan.duty
    knots = [plan.duty, plan.duty + plan.lift_s * swing_span]
    vals = [np.append(a0[1], p0[1]), lift_off + np.append(flat, 0.0)]
    for k in plan.swing:
        x = plan.duty + k[0] * swing_span
        knots.append(x)
        vals.append(np.array([sign * plan.width, k[2], stride * x + k[1], k[3]]))
    knots += [1.0 - plan.lift_s * swing_span, 1.0]
    vals += [landing + np.append(flat + np.array([0.0, 0.0, stride]), 0.0), np.append(a1[0], p1[0])]
    d0 = np.append(a0[1] - a0[0], p0[1] - p0[0]) / h
    d1 = np.append(a1[1] - a1[0], p1[1] - p1[0]) / h
    spline = CubicSpline(knots, np.array(vals), bc_type=((1, d0), (1, d1)), axis=0)
    sw = spline(psi[~st])
    ankle[~st], pitch[~st] = sw[:, :3], sw[:, 3]
    ankle[:, 2] += stride * (phase - psi)
    return ankle, pitch


def column_intent(pelvis: F, spine: F, chest: F, gaze: F) -> tuple[F, F]:
    """Neck and head yaw/pitch/roll that cancel the trunk's rotation half each, plus ``gaze`` pitch."""
    total = pelvis + spine + chest
    neck = -0.5 * total
    head = -0.5 * total
    head[:, 1] += gaze
    return neck, head


def build_gait(skeleton: Skeleton, spec: GaitSpec) -> tuple[Clip, float]:
    """Sample ``spec`` into a looping clip with root motion; also return the largest leg reach used."""
    n = spec.frames
    phase = np.arange(n) / n
    stride = spec.speed * spec.period
    ankles = np.empty((n, 2, 3))
    pitch = np.empty((n, 2))
    for s in range(2):
        toe = skeleton.tips[skeleton.index(f"{'lr'[s]}_foot")]
        ankles[:, s], pitch[:, s] = foot_track(spec.foot, stride, phase, s, toe)
    pos = np.zeros((n, 3))
    pos[:, 0] = _keys.periodic(spec.pelvis_sway, phase)[:, 0]
    pos[:, 1] = _keys.periodic(spec.pelvis_height, phase)[:, 0]
    pos[:, 2] = stride * phase
    pelvis_ypr = _keys.periodic(spec.pelvis_ypr, phase)
    pos[:, 1] = lower_to_reach(skeleton, pos, pelvis_rotation(pelvis_ypr), ankles, spec.max_reach, 3, loop=True)
    spine = _keys.periodic(spec.spine_ypr, phase)
    chest = _keys.periodic(spec.chest_ypr, phase)
    neck, head = column_intent(pelvis_ypr, spine, chest, _keys.periodic(spec.gaze, phase)[:, 0])
    arms = np.stack([_keys.periodic(spec.arm, phase), _keys.periodic(spec.arm, phase - 0.5)], axis=1)
    intent = BodyIntent(
        pelvis_pos=pos,
        pelvis_ypr=pelvis_ypr,
        spine_ypr=spine,
        chest_ypr=chest,
        neck_ypr=neck,
        head_ypr=head,
        arms=arms,
        ankle=ankles,
        foot_pitch=pitch,
        foot_yaw=np.full((n, 2), spec.foot.toe_out),
        travel=np.stack([np.zeros(n), np.zeros(n), stride * phase], axis=-1),
        hand_flex=np.full((n, 2), spec.hand_flex),
    )
    clip, legs = assemble(skeleton, intent, spec.name, spec.fps, True, spec.markers)
    return clip, float(max(legs[0].reach.max(), legs[1].reach.max()))
