"""``cycle --retarget puppet``: a skeletal performance moved onto the puppet before the loop is found.

Retargeting first (rather than the loop after) makes the extractor analyse the puppet's
17 joints — what will play — instead of the actor's 40-odd, and the loop it writes is a
``.ppclip``/BVH on the puppet's skeleton, ready for ``clips add``. The retarget
(:func:`engine.cliplib.source.to_puppet`) scales the root's travel by the leg-length
ratio, so the stride and the speed fit the puppet's legs, and puts the feet on y = 0.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from authoring.cycles.formats import Performance
from authoring.cycles.trajectory import Item, Trajectory, TrajectoryError
from engine.clip import Clip
from engine.cliplib.source import to_puppet
from engine.skeleton import Skeleton

__all__ = ["TARGETS", "retarget_performance", "clip_performance"]

TARGETS = ("puppet",)


def clip_performance(clip: Clip, base: Performance) -> Performance:
    """The performance of a clip: the root's position (travelling) and every joint's rotation."""
    sk = clip.skeleton
    cols = [clip.root]
    names = [f"{sk.names[0]}.{a}" for a in "xyz"]
    items = [Item(f"{sk.names[0]}.position", "position", 0, 3, travel=True)]
    for j, name in enumerate(sk.names):
        start = 3 + 4 * j
        cols.append(clip.rotations[:, j])
        names += [f"{name}.q{a}" for a in "wxyz"]
        items.append(Item(f"{name}.rotation", "rotation", start, start + 4))
    traj = Trajectory.uniform(np.concatenate(cols, axis=1), clip.fps, items)
    return replace(base, trajectory=traj, names=tuple(names), clip=clip, joints=tuple(range(sk.num_joints)))


def retarget_performance(perf: Performance, target: Skeleton) -> Performance:
    """``perf`` played by ``target`` (skeletal input only)."""
    if perf.clip is None:
        raise TrajectoryError("--retarget needs skeletal input (BVH)")
    clip, _ = to_puppet(perf.clip, target)
    return clip_performance(clip, perf)
