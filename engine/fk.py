"""Forward kinematics batched over joints and puppets.

Joints are processed one depth level at a time: every joint of a level, in every
puppet, is composed with its parent in one numpy call. A 17-joint humanoid has
about seven levels, so FK for a hundred puppets is seven vector operations, not
1,700 Python iterations. With numba (:mod:`engine.jit`) a crowd without joint scales
goes through one compiled loop over puppets and joints instead (:func:`fk_kernel`);
the level-by-level numpy walk stays as its twin and reference.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from numpy.typing import ArrayLike, NDArray

from engine import jit, quat
from engine.jit import qmul, qrot
from engine.skeleton import Skeleton

__all__ = ["fk_kernel", "fk_rows", "forward_kinematics", "kernel_array", "levels", "world_points"]


def kernel_array(a: ArrayLike, shape: tuple[int, ...]) -> NDArray[np.float64]:
    """``a`` broadcast to ``shape`` as a C-contiguous, writeable float64 array for a compiled kernel.

    numba types a read-only array apart from a writeable one and compiles the kernel again for it
    (seconds); ``np.broadcast_to`` hands out a read-only view even when ``a`` has ``shape`` already, and
    ``np.ascontiguousarray`` passes such a view through. So ``a`` is broadcast only when its shape
    differs, and copied only when what results is still read-only."""
    out = np.asarray(a, dtype=np.float64)
    out = np.ascontiguousarray(out if out.shape == shape else np.broadcast_to(out, shape))
    return out if out.flags.writeable else out.copy()


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
    if scales is None and jit.enabled():
        n = skeleton.num_joints
        flat_rot = np.ascontiguousarray(rot).reshape(-1, n, 4)
        count = len(flat_rot)
        flat_root = kernel_array(root, batch + (3,)).reshape(count, 3)
        flat_off = kernel_array(off, batch + (n, 3)).reshape(count, n, 3)
        out_pos, out_rot = np.empty((count, n, 3)), np.empty((count, n, 4))
        fk_kernel(skeleton.parents, flat_root, flat_rot, flat_off, out_pos, out_rot)
        return out_pos.reshape(batch + (n, 3)), out_rot.reshape(batch + (n, 4))
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


@jit.njit_inline
def _fk_puppet(
    parents: NDArray[np.int64],
    root: NDArray[np.float64],
    rot: NDArray[np.float64],
    off: NDArray[np.float64],
    r: int,
    p: int,
    out_pos: NDArray[np.float64],
    out_rot: NDArray[np.float64],
    o: int,
) -> None:
    """FK of one puppet, the one loop :func:`fk_kernel` and :func:`fk_rows` share: root and local rotations
    from row ``r`` of ``root``/``rot``, offsets from row ``p`` of ``off``, world pose into row ``o`` of
    ``out_pos``/``out_rot``. Parents before children, each joint ``pos = parent_pos + parent_rot·offset``,
    ``rot = parent_rot·local``, the numpy path's operations."""
    for c in range(3):
        out_pos[o, 0, c] = root[r, c]
    for c in range(4):
        out_rot[o, 0, c] = rot[r, 0, c]
    for j in range(1, rot.shape[1]):
        a = parents[j]
        pq = (out_rot[o, a, 0], out_rot[o, a, 1], out_rot[o, a, 2], out_rot[o, a, 3])
        d = qrot(pq, (off[p, j, 0], off[p, j, 1], off[p, j, 2]))
        out_pos[o, j, 0] = out_pos[o, a, 0] + d[0]
        out_pos[o, j, 1] = out_pos[o, a, 1] + d[1]
        out_pos[o, j, 2] = out_pos[o, a, 2] + d[2]
        q = qmul(pq, (rot[r, j, 0], rot[r, j, 1], rot[r, j, 2], rot[r, j, 3]))
        out_rot[o, j, 0], out_rot[o, j, 1], out_rot[o, j, 2], out_rot[o, j, 3] = q


@jit.njit
def fk_kernel(
    parents: NDArray[np.int64],
    root: NDArray[np.float64],
    rot: NDArray[np.float64],
    off: NDArray[np.float64],
    out_pos: NDArray[np.float64],
    out_rot: NDArray[np.float64],
) -> None:
    """FK of ``P`` puppets into ``out_pos [P,J,3]`` / ``out_rot [P,J,4]``: :func:`_fk_puppet` of each, row ``p``
    to row ``p``."""
    for p in range(rot.shape[0]):
        _fk_puppet(parents, root, rot, off, p, p, out_pos, out_rot, p)


@jit.njit
def fk_rows(
    parents: NDArray[np.int64],
    rows: NDArray[np.int64],
    root: NDArray[np.float64],
    rot: NDArray[np.float64],
    off: NDArray[np.float64],
    out_rows: NDArray[np.int64],
    out_pos: NDArray[np.float64],
    out_rot: NDArray[np.float64],
    prev_pos: NDArray[np.float64],
    prev_rot: NDArray[np.float64],
) -> None:
    """:func:`fk_kernel` in place on a crowd's columns: puppet ``p`` reads row ``rows[p]`` of ``root``/``rot``
    (offsets ``off [P,J,3]``) and writes row ``out_rows[p]`` of ``out_pos``/``out_rot``, after copying that
    row's last values into ``prev_pos``/``prev_rot`` (render interpolation). The rows may be any of the
    arrays' (a crowd that is part of the columns' batch); each puppet's rows are its own."""
    for p in range(rows.shape[0]):
        r, o = rows[p], out_rows[p]
        for j in range(out_pos.shape[1]):
            for c in range(3):
                prev_pos[o, j, c] = out_pos[o, j, c]
            for c in range(4):
                prev_rot[o, j, c] = out_rot[o, j, c]
        _fk_puppet(parents, root, rot, off, r, p, out_pos, out_rot, o)


def world_points(skeleton: Skeleton, wpos: ArrayLike, wrot: ArrayLike) -> NDArray[np.float64]:
    """World positions of each joint's bone tip (its ``tips`` offset), for leaves like feet and head."""
    return np.asarray(wpos) + quat.rotate(wrot, np.broadcast_to(skeleton.tips, np.shape(wpos)))
