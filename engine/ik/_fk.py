"""Single-pose forward kinematics with rotation matrices, for the IK's inner loop.

:func:`engine.fk.forward_kinematics` is built for many puppets at once and walks the
hierarchy level by level; an IK solve evaluates one pose many times, often on deep
chains (a 56-joint tentacle has 56 levels), where a per-level loop of small numpy calls
dominates the whole solve. Here each joint's local transform is a 4×4 matrix and the
world transforms come from *pointer jumping*: every joint holds its transform relative
to some ancestor and that ancestor; each round composes it with the ancestor's own and
jumps to the ancestor's ancestor, so after ``⌈log₂ depth⌉`` rounds (6 for 56 levels, 3
for the humanoid) every transform is relative to the world. Each round is one batched
``matmul`` over all joints. The solver needs matrices anyway (lever arms, axes).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from engine import quat
from engine.skeleton import Skeleton

__all__ = ["fk_matrices"]

from engine.arrays import F64 as F

# by the next one allocated, which then silently got another hierarchy's table.
_JUMPS: dict[bytes, list[NDArray[np.int64]]] = {}


def _jumps(skeleton: Skeleton) -> list[NDArray[np.int64]]:
    """Per round, the ancestor each joint composes with (index ``J`` is the identity)."""
    parents = np.asarray(skeleton.parents, dtype=np.int64)
    key = parents.tobytes()
    hit = _JUMPS.get(key)
    if hit is not None:
        return hit
    n = skeleton.num_joints
    anc = np.where(parents < 0, n, parents).astype(np.int64)
    anc = np.r_[anc, n]
    rounds = []
    while np.any(anc[:n] != n):
        rounds.append(anc.copy())
        anc = anc[anc]
    _JUMPS[key] = rounds or [np.full(n + 1, n, dtype=np.int64)]
    return _JUMPS[key]


def fk_matrices(
    skeleton: Skeleton, root: ArrayLike, rotations: ArrayLike, offsets: ArrayLike | None = None
) -> tuple[F, F]:
    """World positions ``[J,3]`` and world rotation matrices ``[J,3,3]`` of one pose."""
    n = skeleton.num_joints
    off = skeleton.offsets if offsets is None else np.asarray(offsets, dtype=np.float64)
    t = np.zeros((n + 1, 4, 4))
    t[:n, :3, :3] = quat.to_matrix(rotations)
    t[:n, :3, 3] = off
    t[0, :3, 3] = root
    t[:, 3, 3] = 1.0
    t[n, :3, :3] = np.eye(3)
    for anc in _jumps(skeleton):
        t = t[anc] @ t
    return t[:n, :3, 3].copy(), t[:n, :3, :3].copy()
