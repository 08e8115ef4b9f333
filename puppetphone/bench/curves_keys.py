"""Thesis Table 4.1 like for like: keys needed to reach a target motion, Motion Curves against plain keyframing.

For three motions — a wave (synthetic: the right arm raised, the forearm swinging at 2 Hz,
built here because no clip waves), the default walk cycle and the default jump
(``mid_jump``) — a scripted author works in the same tool (:class:`CurveSession`) from a
clip holding only its end poses, until every tracked joint (hands, feet, head, hips) is
within ``TOLERANCE`` of the target at every frame:

- **keyframing**: only keys. Each step adds a key at the frame of the largest miss and
  poses it as the target's pose there (tangents automatic, Catmull-Rom): 2 operations.
- **Motion Curves**: the same, except that a miss between keys is first dragged onto the
  target with the tangent solver (the tracked joint's trajectory at that frame): 1
  operation; only when the drag does not lower the largest miss is a key added instead.

The figures are the final key counts (``keys_<motion>_motion_curves`` against
``keys_<motion>_keyframing`` as its baseline) and operations of each. A scripted greedy
author is not the thesis' animators (Table 4.1 counts keys artists set by hand), so the
counts compare the two ways of working in this tool, not this tool with Maya.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from authoring.keyframe_curves.keys import MIN_KEY_GAP_FRAMES, key_frames, pose_channels, set_key_channels
from authoring.keyframe_curves.session import CurveSession
from engine import quat
from engine.clip import Clip
from engine.clips import default_clips
from engine.keyframes import BezierCurves, KeyframedClip
from puppetphone.bench.figures import Figure

__all__ = ["run", "author", "wave_clip", "TOLERANCE", "TRACKED", "MOTIONS"]

TOLERANCE = 0.01  # metres, every tracked joint at every frame
TRACKED = ("hips", "head", "l_hand", "r_hand", "l_foot", "r_foot")
MOTIONS = ("wave", "walk", "jump")
MAX_STEPS = 80


def wave_clip() -> Clip:
    """One second (60 frames, looping) of the idle pose with the right arm up and the forearm waving at 2 Hz."""
    idle = default_clips()["idle"]
    sk = idle.skeleton
    n = 60
    t = np.arange(n) / 60.0
    rot = np.repeat(idle.rotations[:1], n, axis=0)
    up = quat.from_axis_angle(np.array([0.0, 0.0, 1.0]), -2.4)  # the right arm raised to the side
    rot[:, sk.index("r_upper_arm")] = quat.mul(up, rot[0, sk.index("r_upper_arm")])
    swing = quat.from_axis_angle(np.array([[0.0, 0.0, 1.0]] * n), 0.35 + 0.45 * np.sin(2 * np.pi * 2.0 * t))
    rot[:, sk.index("r_lower_arm")] = quat.mul(swing, rot[0, sk.index("r_lower_arm")])
    return Clip("wave", sk, 60.0, np.repeat(idle.root[:1], n, axis=0), rot, loop=True)


def _target(motion: str) -> Clip:
    if motion == "wave":
        return wave_clip()
    clip = default_clips()["mid_jump" if motion == "jump" else motion]
    return replace(clip, root_motion=None)


def _positions(clip: KeyframedClip | Clip, joints: list[int]) -> np.ndarray:
    """``[F,T,3]`` the tracked joints at every frame (a loop's seam frame included for keyframed clips)."""
    from engine.fk import forward_kinematics

    baked = clip.bake() if isinstance(clip, KeyframedClip) else clip
    out = [
        forward_kinematics(baked.skeleton, baked.root[f], baked.rotations[f])[0][joints]
        for f in range(baked.num_frames)
    ]
    return np.array(out)


def _channels(target: Clip, frame: int, near: np.ndarray | None) -> np.ndarray:
    return pose_channels(target.root[frame], target.rotations[frame], near=near)


def _blocking(target: Clip) -> KeyframedClip:
    """The author's start: the target's first pose at both ends (its last pose too when it does not loop)."""
    n = target.num_frames
    last = n if target.loop else n - 1
    first = _channels(target, 0, None)
    end = first if target.loop else _channels(target, n - 1, first)
    values = np.stack([first, end])
    gap = np.full_like(values, last / target.fps / 3.0)
    curves = BezierCurves(np.array([0.0, last / target.fps]), values, gap, np.zeros_like(values), gap.copy(),
                          np.zeros_like(values))  # fmt: skip
    clip = KeyframedClip(target.name, target.skeleton, curves, target.fps, target.loop)
    return set_key_channels(set_key_channels(clip, 0, first), 1, end)


def _free(clip: KeyframedClip, frame: int) -> bool:
    keys = key_frames(clip)
    return bool(np.all(np.abs(keys - frame) >= MIN_KEY_GAP_FRAMES))


def _drag_in(
    session: CurveSession, target: Clip, joints: list[int], goal: np.ndarray, frame: int, miss: np.ndarray
) -> bool:
    """Drag each tracked joint that misses at ``frame`` onto its target there (worst first); keep a drag that
    lowers the miss at that frame without raising the largest miss anywhere. True when one was kept."""
    sk = target.skeleton
    t = session.clip.curves.times[0] + frame / target.fps
    worst = float(miss.max())
    for i in np.argsort(miss[frame])[::-1]:
        if miss[frame, i] <= TOLERANCE:
            break
        before = session.clip
        try:
            session.drag(sk.names[joints[i]], t, position=goal[frame, i])
        except ValueError:  # on a key: nothing between keys to shape
            return False
        if session.clip is before:
            continue
        now = np.linalg.norm(_positions(session.clip, joints)[: len(goal)] - goal, axis=-1)
        if now[frame].max() < miss[frame].max() - 1e-4 and now.max() <= worst + 1e-6:
            return True
        session.undo()
    return False


def author(motion: str, curves: bool) -> tuple[int, int, float]:
    """``(keys, operations, largest miss in metres)`` for the scripted author on ``motion``."""
    target = _target(motion)
    sk = target.skeleton
    joints = [sk.index(j) for j in TRACKED]
    goal = _positions(target, joints)
    session = CurveSession(_blocking(target))
    ops = 0
    for _ in range(MAX_STEPS):
        miss = np.linalg.norm(_positions(session.clip, joints)[: len(goal)] - goal, axis=-1)  # [F,T]
        if miss.max() <= TOLERANCE:
            break
        order = np.argsort(miss.max(axis=1))[::-1]
        frame = next((int(f) for f in order if _free(session.clip, int(f))), None)
        if frame is None:
            break  # keys on every frame that could take one
        float(miss.max())
        if curves and _drag_in(session, target, joints, goal, frame, miss):
            ops += 1
            continue
        near = session.clip.coordinates([session.clip.curves.times[0] + frame / target.fps])[0]
        session.add_key(frame)
        session.set_key(int(np.nonzero(key_frames(session.clip) == frame)[0][0]), _channels(target, frame, near))
        ops += 2
    miss = np.linalg.norm(_positions(session.clip, joints)[: len(goal)] - goal, axis=-1)
    return int(session.clip.curves.times.size), ops, float(miss.max())


def run() -> list[Figure]:
    """Keys and operations per motion, Motion Curves beside plain keyframing (its baseline)."""
    figures = []
    for motion in MOTIONS:
        k_keys, k_ops, k_miss = author(motion, curves=False)
        m_keys, m_ops, m_miss = author(motion, curves=True)
        figures.append(Figure("curves", f"keys_{motion}_motion_curves", float(m_keys), "keys",
                              f"keys_{motion}_keyframing (plain keys, same tool)", float(k_keys)))  # fmt: skip
        figures.append(Figure("curves", f"ops_{motion}_motion_curves", float(m_ops), "operations",
                              f"ops_{motion}_keyframing", float(k_ops)))  # fmt: skip
        figures.append(Figure("curves", f"miss_mm_{motion}_motion_curves", m_miss * 1e3, "mm",
                              "tolerance", TOLERANCE * 1e3))  # fmt: skip
        figures.append(
            Figure("curves", f"miss_mm_{motion}_keyframing", k_miss * 1e3, "mm", "tolerance", TOLERANCE * 1e3)
        )
    return figures
