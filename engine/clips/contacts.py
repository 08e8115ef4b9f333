"""Foot contacts and foot sliding of a clip, measured in the world with root motion applied.

A foot touches the ground where its lowest sole point (heel or toe tip) is near the floor
and nearly still. The same lowest point measures sliding: during heel strike the heel is
the pivot, during push-off the toe tip is, in between both rest, so the lowest point's
horizontal speed is what an onlooker sees as a skating foot.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from engine import quat
from engine.arrays import F64 as F
from engine.clip import Clip
from engine.fk import forward_kinematics

__all__ = ["HEEL_OFFSET", "FOOT_JOINTS", "world_poses", "sole_points", "foot_contacts", "foot_sliding"]


HEEL_OFFSET = np.array([0.0, -0.05, -0.05])
"""Back of the heel in the foot joint's frame: level with the toe tip, 5 cm behind the ankle."""

FOOT_JOINTS = ("l_foot", "r_foot")
_UP = np.array([0.0, 1.0, 0.0])


def world_poses(clip: Clip, closing: bool = False) -> tuple[F, F]:
    """World joint positions and rotations ``[F(+1),J,·]`` with the root motion applied.

    With ``closing`` a looping clip gets one extra frame: its first frame one cycle later,
    so differences across the loop seam can be taken.
    """
    root, rot = clip.root, clip.rotations
    trans = np.zeros_like(root)
    head = np.zeros(len(root))
    if clip.root_motion is not None:
        trans, head = clip.root_motion.translation, clip.root_motion.heading
    if closing and clip.loop:
        ct, ch = clip.cycle_travel()
        root = np.vstack([root, root[:1]])
        rot = np.concatenate([rot, rot[:1]])
        trans = np.vstack([trans, trans[:1] + ct])
        head = np.append(head, head[0] + ch)
    yaw = quat.from_axis_angle(_UP, head)
    world_rot = rot.copy()
    world_rot[:, 0] = quat.mul(yaw, rot[:, 0])
    pos, wrot = forward_kinematics(clip.skeleton, quat.rotate(yaw, root) + trans, world_rot)
    return pos, wrot


def sole_points(clip: Clip, closing: bool = False) -> F:
    """``[F(+1),2,2,3]`` world heel and toe-tip points (side, heel/toe, xyz) of both feet."""
    pos, rot = world_poses(clip, closing)
    idx = [clip.skeleton.index(n) for n in FOOT_JOINTS]
    tips = clip.skeleton.tips[idx]
    out = np.empty(pos.shape[:1] + (2, 2, 3))
    for s, j in enumerate(idx):
        out[:, s, 0] = pos[:, j] + quat.rotate(rot[:, j], HEEL_OFFSET)
        out[:, s, 1] = pos[:, j] + quat.rotate(rot[:, j], tips[s])
    return out


def _lowest_track(clip: Clip) -> tuple[F, F]:
    """Lowest sole point per frame and side ``[F,2,3]`` and its velocity ``[F,2,3]`` (m/s)."""
    pts = sole_points(clip, closing=True)
    low = np.argmin(pts[..., 1], axis=-1)  # [F+1, 2]: heel (0) or toe (1)
    pick = np.take_along_axis(pts, low[..., None, None], axis=2)[:, :, 0]
    # Follow the same point over each step so a heel→toe hand-over is not read as motion.
    nxt = np.take_along_axis(pts[1:], low[:-1, :, None, None], axis=2)[:, :, 0]
    vel = (nxt - pick[:-1]) * clip.fps
    if clip.loop:
        return pick[:-1], vel
    last = vel[-1:] if len(vel) else np.zeros((1, 2, 3))
    return pick, np.vstack([vel, last])


def foot_contacts(clip: Clip, max_height: float = 0.03, max_speed: float = 0.3) -> NDArray[np.bool_]:
    """``[F,2]`` (left, right): whether each foot is on the ground in each frame.

    Args:
        clip: any clip of a skeleton with ``l_foot`` and ``r_foot``.
        max_height: highest the lowest sole point may be above the floor (y = 0), metres; the
            default puppet's sole rests 1 cm up, so this allows 2 cm of hover.
        max_speed: fastest it may move, m/s; a swinging foot skimming the floor is faster.
    """
    low, vel = _lowest_track(clip)
    return (low[..., 1] <= max_height) & (np.linalg.norm(vel, axis=-1) <= max_speed)


def foot_sliding(clip: Clip, contacts: NDArray[np.bool_] | None = None) -> F:
    """Mean horizontal speed (m/s) of each foot's lowest sole point while in contact, ``[2]``.

    A foot that is never in contact scores 0.
    """
    low, vel = _lowest_track(clip)
    c = foot_contacts(clip) if contacts is None else np.asarray(contacts, dtype=bool)
    if c.shape != low.shape[:2]:
        raise ValueError(f"contacts must be [{len(low)},2] bool, got {c.shape}")
    speed = np.linalg.norm(vel[..., [0, 2]], axis=-1)
    return np.array([speed[c[:, s], s].mean() if c[:, s].any() else 0.0 for s in range(2)])
