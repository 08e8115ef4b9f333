"""Boxes around ragdolls in their current poses, for deciding who must be in the model.

:mod:`engine.ragdoll._islands` compares these boxes; this module makes them, from the two
places a pose lives: MuJoCo's geoms for a ragdoll simulated now (its capsules where the last
substep left them), or the command (root and local rotations, through forward kinematics) for
one that is animated or has not been placed yet. A MuJoCo body frame is the skeleton joint's
frame (:mod:`engine.ragdoll.mjcf`), so both give the same capsules for the same pose.
"""

from __future__ import annotations

import mujoco
import numpy as np
from numpy.typing import NDArray

from engine import quat
from engine.arrays import F64 as _F
from engine.fk import forward_kinematics
from engine.ragdoll._islands import capsule_boxes
from engine.ragdoll.mjcf import RagdollSpec
from engine.ragdoll.profile import bone_segments

__all__ = ["command_boxes", "geom_boxes"]


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
