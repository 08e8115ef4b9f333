"""Boxes around ragdolls in their current poses, for deciding who must be in the model.

:mod:`engine.ragdoll._islands` compares these boxes; this module makes them, from the two
places a pose lives: MuJoCo's geoms for a ragdoll simulated now (its capsules where the last
substep left them), or the command (root and local rotations, through forward kinematics) for
one that is animated or has not been placed yet. A MuJoCo body frame is the skeleton joint's
frame (:mod:`engine.ragdoll.mjcf`), so both give the same capsules for the same pose.

The command boxes are made every step for every animated ragdoll near something simulated (the
snowman game: five snowmen of five kinds near its rolling balls; a fall: some fifty walkers): per
kind, forward kinematics, two rotations and a reduction were a dozen numpy passes, 2 ms of the
snowman's step. :func:`posed_boxes` makes the boxes of any mix of kinds in one compiled loop (the
kinds' capsules and hierarchies in flat tables, :class:`KindTable`), with the operations of the FK
kernel and of :func:`command_boxes` in their order: the same boxes bit for bit.
"""

from __future__ import annotations

import mujoco
import numpy as np
from numpy.typing import NDArray

from engine import jit, quat
from engine.arrays import F64 as _F
from engine.fk import forward_kinematics
from engine.jit import qmul, qrot
from engine.ragdoll._islands import capsule_boxes
from engine.ragdoll.mjcf import RagdollSpec
from engine.ragdoll.profile import bone_segments

__all__ = ["KindTable", "command_boxes", "geom_boxes", "load", "posed_boxes"]


_SEGMENTS: dict[bytes, tuple[_F, _F, _F]] = {}


def _segments(kind: bytes, spec: RagdollSpec) -> tuple[_F, _F, _F]:
    """The capsules of a kind of ragdoll in its joint frames (``kind`` keys the cache: specs of one
    kind render the same bodies, :func:`engine.ragdoll._pool.kind_of`)."""
    if kind not in _SEGMENTS:
        _SEGMENTS[kind] = bone_segments(spec.skeleton, spec.profile.radii, spec.offsets)
    return _SEGMENTS[kind]


def command_boxes(kind: bytes, spec: RagdollSpec, roots: _F, rotations: _F) -> _F:
    """Boxes ``[n,2,3]`` of ``n`` ragdolls of one kind (``spec`` one of them) posed at ``roots [n,3]``
    with local ``rotations [n,J,4]``."""
    p0, p1, r = _segments(kind, spec)
    n, joints = len(roots), spec.skeleton.num_joints
    wpos, wrot = forward_kinematics(spec.skeleton, roots, rotations, spec.offsets)
    a = (wpos + quat.rotate(wrot, np.broadcast_to(p0, wpos.shape))).reshape(-1, 3)
    b = (wpos + quat.rotate(wrot, np.broadcast_to(p1, wpos.shape))).reshape(-1, 3)
    return capsule_boxes(a, b, np.tile(r, n), np.repeat(np.arange(n), joints), n)


def geom_boxes(
    m: mujoco.MjModel, d: mujoco.MjData, geoms: NDArray[np.int64], owner: NDArray[np.int64], count: int
) -> _F:
    """Boxes ``[count,2,3]`` around MuJoCo's capsule and sphere ``geoms`` where they are now,
    geom ``i`` belonging to box ``owner[i]`` (sorted)."""
    centre = d.geom_xpos[geoms]
    axis = d.geom_xmat[geoms].reshape(-1, 3, 3)[:, :, 2]
    half = np.where(m.geom_type[geoms] == int(mujoco.mjtGeom.mjGEOM_CAPSULE), m.geom_size[geoms, 1], 0.0)
    return capsule_boxes(
        centre - axis * half[:, None], centre + axis * half[:, None], m.geom_size[geoms, 0], owner, count
    )


class KindTable:
    """Every kind's hierarchy, bone offsets and capsules end to end, for :func:`posed_boxes`: kind
    ``k``'s joints are rows ``start[k]:start[k+1]`` of ``parents``, ``offsets``, ``p0``, ``p1``, ``radius``
    (its capsules from ``p0`` to ``p1`` in the joint frames). A kind is added the first time it is seen."""

    def __init__(self) -> None:
        self.index: dict[bytes, int] = {}
        self.start: NDArray[np.int64] = np.zeros(1, dtype=np.int64)
        self.parents: NDArray[np.int64] = np.zeros(0, dtype=np.int64)
        self.offsets: _F = np.zeros((0, 3))
        self.p0: _F = np.zeros((0, 3))
        self.p1: _F = np.zeros((0, 3))
        self.radius: _F = np.zeros(0)

    def of(self, kind: bytes, spec: RagdollSpec) -> int:
        """The table index of ``kind`` (``spec`` one ragdoll of it), adding its rows if new."""
        k = self.index.get(kind)
        if k is None:
            p0, p1, r = _segments(kind, spec)
            k = self.index[kind] = len(self.index)
            self.start = np.append(self.start, self.start[-1] + spec.skeleton.num_joints)
            self.parents = np.concatenate([self.parents, np.asarray(spec.skeleton.parents, dtype=np.int64)])
            self.offsets = np.concatenate([self.offsets, np.asarray(spec.offsets, dtype=np.float64)])
            self.p0, self.p1 = np.concatenate([self.p0, p0]), np.concatenate([self.p1, p1])
            self.radius = np.concatenate([self.radius, r])
        return k


@jit.njit
def _posed_boxes(
    kinds: NDArray[np.int64],
    start: NDArray[np.int64],
    parents: NDArray[np.int64],
    offsets: _F,
    p0: _F,
    p1: _F,
    radius: _F,
    roots: _F,
    rot: _F,
    first: NDArray[np.int64],
    out: _F,
) -> None:
    """Box ``out[n]`` of ragdoll ``n`` of kind ``kinds[n]``, rooted at ``roots[n]`` with local rotations
    ``rot[first[n]:]``: forward kinematics as :func:`engine.fk.fk_kernel` computes it, capsule ends as
    :func:`command_boxes` rotates them, low and high corners as :func:`capsule_boxes` reduces them."""
    joints = start[1:] - start[:-1]
    wpos = np.empty((joints.max(), 3))
    wrot = np.empty((joints.max(), 4))
    for n in range(kinds.shape[0]):
        s, c = start[kinds[n]], first[n]
        for k in range(3):
            wpos[0, k] = roots[n, k]
        for k in range(4):
            wrot[0, k] = rot[c, k]
        for j in range(1, joints[kinds[n]]):
            a = parents[s + j]
            pq = (wrot[a, 0], wrot[a, 1], wrot[a, 2], wrot[a, 3])
            d = qrot(pq, (offsets[s + j, 0], offsets[s + j, 1], offsets[s + j, 2]))
            for k in range(3):
                wpos[j, k] = wpos[a, k] + d[k]
            q = qmul(pq, (rot[c + j, 0], rot[c + j, 1], rot[c + j, 2], rot[c + j, 3]))
            wrot[j, 0], wrot[j, 1], wrot[j, 2], wrot[j, 3] = q
        for j in range(joints[kinds[n]]):
            q = (wrot[j, 0], wrot[j, 1], wrot[j, 2], wrot[j, 3])
            ea = qrot(q, (p0[s + j, 0], p0[s + j, 1], p0[s + j, 2]))
            eb = qrot(q, (p1[s + j, 0], p1[s + j, 1], p1[s + j, 2]))
            r = radius[s + j]
            for k in range(3):
                a_k, b_k = wpos[j, k] + ea[k], wpos[j, k] + eb[k]
                lo, hi = min(a_k, b_k) - r, max(a_k, b_k) + r
                out[n, 0, k] = lo if j == 0 else min(out[n, 0, k], lo)
                out[n, 1, k] = hi if j == 0 else max(out[n, 1, k], hi)


def posed_boxes(table: KindTable, kinds: NDArray[np.int64], roots: _F, rot: _F, first: NDArray[np.int64]) -> _F:
    """Boxes ``[n,2,3]`` of ragdolls of table kinds ``kinds [n]`` at ``roots [n,3]``, ragdoll ``i``'s local
    rotations the rows of ``rot`` from ``first[i]`` on: :func:`command_boxes` of each (compiled; numba
    must be installed)."""
    out = np.empty((len(kinds), 2, 3))
    if len(kinds):
        _posed_boxes(
            kinds, table.start, table.parents, table.offsets, table.p0, table.p1, table.radius, roots, rot, first, out
        )
    return out


def load() -> None:
    """Load :func:`posed_boxes`' kernel now (see :func:`engine.ragdoll._drive_kernel.load`)."""
    i, f2 = np.zeros(0, np.int64), np.zeros((0, 3))
    _posed_boxes(i, np.zeros(2, np.int64), i, f2, f2, f2, np.zeros(0), f2, f2, i, np.zeros((0, 2, 3)))
