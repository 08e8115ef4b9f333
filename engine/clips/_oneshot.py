"""One-shot clips blocked as key poses: get-up and mid-jump.

Each key is a whole-body pose at a time; between keys every channel is interpolated with
PCHIP, which eases without overshoot (a hip that rises from the floor never dips into it).
Legs are keyed as ankle positions in the world and solved by the leg IK, so a foot keyed at
the same place in consecutive keys stays planted while the body rises over it. Hands are
keyed as angles and kept out of the floor afterwards: where interpolation between two key
poses would push a hand through the ground (a trunk still reclined while the arm already
reaches back), the arm is swung out sideways just enough to rest on it, as a person
propping themselves up does.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from engine.arrays import F64 as F
from engine.clip import Clip
from engine.clips import _keys
from engine.clips._body import BodyIntent, assemble, upper_body_rotations
from engine.clips._reach import smooth_envelope
from engine.fk import forward_kinematics, world_points
from engine.skeleton import Skeleton

__all__ = ["PoseKey", "key_from_intent", "build_one_shot", "hands_above_floor"]

V3 = tuple[float, float, float]


@dataclass(frozen=True)
class PoseKey:
    """A whole-body key pose at time ``t`` (seconds). Angles in degrees, positions in metres.

    ``arms``, ``ankles``, ``foot_pitch``, ``foot_yaw`` and ``hand`` are (left, right) pairs;
    see :class:`engine.clips._body.BodyIntent` for each channel's sign convention.
    """

    t: float
    pelvis: V3
    pelvis_ypr: V3
    spine: V3
    chest: V3
    neck: V3
    head: V3
    arms: tuple[V3, V3]
    ankles: tuple[V3, V3]
    foot_pitch: tuple[float, float]
    foot_yaw: tuple[float, float] = (6.0, 6.0)
    hand: tuple[float, float] = (8.0, 8.0)

    def at(self, t: float) -> PoseKey:
        """The same pose at another time (a hold)."""
        return PoseKey(
            t,
            self.pelvis,
            self.pelvis_ypr,
            self.spine,
            self.chest,
            self.neck,
            self.head,
            self.arms,
            self.ankles,
            self.foot_pitch,
            self.foot_yaw,
            self.hand,
        )


_FIELDS = ("pelvis", "pelvis_ypr", "spine", "chest", "neck", "head", "arms", "ankles", "foot_pitch", "foot_yaw", "hand")


def key_from_intent(intent: BodyIntent, i: int, t: float) -> PoseKey:
    """Frame ``i`` of a solved intent as a key pose (used to end get-up on idle's first frame)."""

    def v3(a: F) -> V3:
        return (float(a[0]), float(a[1]), float(a[2]))

    hand = (8.0, 8.0) if intent.hand_flex is None else (float(intent.hand_flex[i, 0]), float(intent.hand_flex[i, 1]))
    return PoseKey(
        t,
        v3(intent.pelvis_pos[i]),
        v3(intent.pelvis_ypr[i]),
        v3(intent.spine_ypr[i]),
        v3(intent.chest_ypr[i]),
        v3(intent.neck_ypr[i]),
        v3(intent.head_ypr[i]),
        (v3(intent.arms[i, 0]), v3(intent.arms[i, 1])),
        (v3(intent.ankle[i, 0]), v3(intent.ankle[i, 1])),
        (float(intent.foot_pitch[i, 0]), float(intent.foot_pitch[i, 1])),
        (float(intent.foot_yaw[i, 0]), float(intent.foot_yaw[i, 1])),
        hand,
    )


def hands_above_floor(
    skeleton: Skeleton, intent: BodyIntent, clearance: float = 0.02, radius: int = 4, iters: int = 30
) -> BodyIntent:
    """``intent`` with shoulder abduction raised where a hand tip would be below ``clearance``.

    Abduction lifts a downward-pointing arm monotonically, so a bisection per frame (all
    frames at once) finds the least abduction that keeps the hand on the floor surface; the
    added abduction is then eased in and out over ``radius`` frames (never below what each
    frame needs), so the arm swings out rather than snapping.
    """
    hands = [skeleton.index(f"{s}_hand") for s in ("l", "r")]

    def tip_heights(arms: F) -> F:
        trial = replace(intent, arms=arms)
        pos, rot = forward_kinematics(skeleton, intent.pelvis_pos, upper_body_rotations(skeleton, trial))
        return world_points(skeleton, pos, rot)[:, hands, 1]

    arms = intent.arms.copy()
    low = tip_heights(arms) < clearance  # [N,2]
    if not low.any():
        return intent
    lo, hi = arms[..., 1].copy(), np.full(arms.shape[:2], 100.0)
    for _ in range(iters):
        mid = 0.5 * (lo + hi)
        arms[..., 1] = np.where(low, mid, arms[..., 1])
        ok = tip_heights(arms) >= clearance
        hi = np.where(low & ok, mid, hi)
        lo = np.where(low & ~ok, mid, lo)
    lift = np.where(low, hi - intent.arms[..., 1], 0.0)
    arms[..., 1] = intent.arms[..., 1] + smooth_envelope(lift, radius, loop=False)
    return replace(intent, arms=arms)


def build_one_shot(
    skeleton: Skeleton,
    name: str,
    keys: tuple[PoseKey, ...],
    fps: float = 60.0,
    travel: bool = False,
) -> tuple[Clip, float]:
    """Sample key poses into a non-looping clip; return it and the largest leg reach used.

    With ``travel`` the pelvis's ground-plane path becomes root motion (get-up rises over
    feet ahead of where it lay), so the clip ends with its root over the origin like the
    idle it hands over to. Only the forward (z) travel is extracted; sideways sway stays in the clip.
    """
    if len(keys) < 2:
        raise ValueError(f"{name}: a one-shot clip needs at least two keys")
    times = [k.t for k in keys]
    n = int(round((times[-1] - times[0]) * fps)) + 1
    t = times[0] + np.arange(n) / fps
    tracks = {}
    for f in _FIELDS:
        vals = [(k.t, np.ravel(np.asarray(getattr(k, f), dtype=np.float64))) for k in keys]
        tracks[f] = _keys.one_shot(vals, t)
    pos = tracks["pelvis"]
    intent = BodyIntent(
        pelvis_pos=pos,
        pelvis_ypr=tracks["pelvis_ypr"],
        spine_ypr=tracks["spine"],
        chest_ypr=tracks["chest"],
        neck_ypr=tracks["neck"],
        head_ypr=tracks["head"],
        arms=tracks["arms"].reshape(n, 2, 3),
        ankle=tracks["ankles"].reshape(n, 2, 3),
        foot_pitch=tracks["foot_pitch"],
        foot_yaw=tracks["foot_yaw"],
        travel=pos * np.array([0.0, 0.0, 1.0]) if travel else None,
        hand_flex=tracks["hand"],
    )
    clip, legs = assemble(skeleton, hands_above_floor(skeleton, intent), name, fps, False)
    return clip, float(max(legs[0].reach.max(), legs[1].reach.max()))
