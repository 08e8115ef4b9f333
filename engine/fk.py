"""Forward kinematics batched over joints and puppets.

Joints are processed one depth level at a time: every joint of a level, in every
puppet, is composed with its parent in one numpy call. A 17-joint humanoid has
about seven levels, so FK for a hundred puppets is seven vector operations, not
1,700 Python iterations.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from numpy.typing import ArrayLike, NDArray

from engine import quat
from engine.skeleton import Skeleton

__all__ = ["forward_kinematics", "world_points", "levels"]


@lru_cache(maxsize=64)
def _levels(parents: bytes) -> tuple[tuple[NDArray[np.int64], NDArray[np.int64]], ...]:
    par = np.frombuffer(parents, dtype=np.int64)
    depth = np.zeros(len(par), dtype=np.int64)
    for j in range(1, len(par)):
        depth[j] = depth[par[j]] + 1
    out = []
    for d in range(1, int(depth.max(initial=0)) + 1):
        idx = np.nonzero(depth == d)[0]
        out.append((idx, par[idx]))
    return tuple(out)


def levels(skeleton: Skeleton) -> tuple[tuple[NDArray[np.int64], NDArray[np.int64]], ...]:
    """``(joints, their parents)`` per depth level below the root, cached per hierarchy."""
    return _levels(skeleton.parents.tobytes())


def forward_kinematics(
    skeleton: Skeleton,
    root: ArrayLike,
    rotations: ArrayLike,
    offsets: ArrayLike | None = None,
    scales: ArrayLike | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """World positions ``[...,J,3]`` and rotations ``[...,J,4]`` of every joint.

    Args:
        skeleton: the hierarchy.
        root: ``[...,3]`` world position of joint 0.
        rotations: ``[...,J,4]`` local rotations (joint 0's is its world rotation).
        offsets: optional ``[...,J,3]`` per-puppet offsets (snowmen have their own bone
            lengths, clips with a translation channel); defaults to the skeleton's.
        scales: optional ``[...,J]`` uniform joint scales (a clip's scale channel): a joint's
            scale multiplies the offsets of everything below it, as glTF's node scale does.
    """
    rot = np.asarray(rotations, dtype=np.float64)
    off = skeleton.offsets if offsets is None else np.asarray(offsets, dtype=np.float64)
    batch = rot.shape[:-2]
    wpos = np.empty(batch + (skeleton.num_joints, 3))
    wrot = np.empty(batch + (skeleton.num_joints, 4))
    wpos[..., 0, :] = np.asarray(root, dtype=np.float64)
    wrot[..., 0, :] = rot[..., 0, :]
    off = np.broadcast_to(off, batch + (skeleton.num_joints, 3))
    if scales is not None:
        # Accumulate world scale down the levels, then scale each offset by its parent's.
        wscale = np.array(np.broadcast_to(np.asarray(scales, dtype=np.float64), batch + (skeleton.num_joints,)))
        for idx, par in levels(skeleton):
            wscale[..., idx] *= wscale[..., par]
        par_all = np.maximum(skeleton.parents, 0)
        off = off * wscale[..., par_all][..., None]
    for idx, par in levels(skeleton):
        prot = wrot[..., par, :]
        wpos[..., idx, :] = wpos[..., par, :] + quat.rotate(prot, off[..., idx, :])
        wrot[..., idx, :] = quat.mul(prot, rot[..., idx, :])
    return wpos, wrot


def world_points(skeleton: Skeleton, wpos: ArrayLike, wrot: ArrayLike) -> NDArray[np.float64]:
    """World positions of each joint's bone tip (its ``tips`` offset), for leaves like feet and head."""
    return np.asarray(wpos) + quat.rotate(wrot, np.broadcast_to(skeleton.tips, np.shape(wpos)))
