"""Per-frame local tracks shared by the BVH and glTF importers.

Both formats can animate the translation of any joint, while a :class:`~engine.clip.Clip`
moves only joint 0. Importers therefore work on full local tracks (translations
``[F,J,3]``, rotations ``[F,J,4]``) and call :func:`fold_root` before building the clip.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from engine import quat
from engine.arrays import F64

__all__ = ["fold_root"]


def fold_root(
    names: list[str], parents: NDArray[np.int64], trans: F64, rots: F64, moves: NDArray[np.bool_], tips: F64
) -> tuple[list[str], NDArray[np.int64], F64, F64, NDArray[np.bool_], F64]:
    """Fold joint 0 into its only child while a chain of only children below it has animated translation.

    Exact: the child's world transform ``T0 · T1`` becomes its own, so the travel that a
    static ``joint_Root`` (Bandai) or ``b_Root_00`` (Fox) leaves to the hips lands on the
    clip's root. Joints must be in topological order with the only child at index 1.
    """
    while len(names) > 1 and _moving_only_child(parents, moves) and not np.any(tips[0]):
        trans[:, 1] = trans[:, 0] + quat.rotate(rots[:, 0], trans[:, 1])
        rots[:, 1] = quat.mul(rots[:, 0], rots[:, 1])
        names, trans, rots, moves, tips = names[1:], trans[:, 1:], rots[:, 1:], moves[1:], tips[1:]
        parents = np.maximum(parents[1:] - 1, -1)
    return names, parents, trans, rots, moves, tips


def _moving_only_child(parents: NDArray[np.int64], moves: NDArray[np.bool_]) -> bool:
    """Whether joint 0 has one child (index 1) and that chain of only children holds a moving joint."""
    j = 0
    while True:
        kids = np.nonzero(parents == j)[0]
        if len(kids) != 1 or kids[0] != j + 1:
            return False
        j += 1
        if moves[j]:
            return True
