"""Poses: a root translation plus local joint rotations, batched over any leading axes.

A pose is plain array data, ``root [...,3]`` and ``rotations [...,J,4]`` (unit quaternions,
w first), and, only when the clip it came from animates them, local joint ``offsets
[...,J,3]`` and uniform joint ``scales [...,J]`` (``None`` otherwise: the skeleton's rest
offsets and scale 1, at no cost). The same class holds one pose, a clip's frames ``[F,J,4]`` or a crowd
``[P,J,4]``; every operation is vectorised over the leading axes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from engine import quat
from engine.skeleton import Skeleton

__all__ = ["Pose"]


@dataclass
class Pose:
    """Root translation in world (or clip) space and local joint rotations."""

    root: NDArray[np.float64]
    rotations: NDArray[np.float64]
    offsets: NDArray[np.float64] | None = None
    scales: NDArray[np.float64] | None = None

    @classmethod
    def rest(cls, skeleton: Skeleton, *batch: int) -> Pose:
        """The rest pose: identity rotations, the root at its rest offset."""
        root = np.broadcast_to(skeleton.offsets[0], (*batch, 3)).copy()
        return cls(root, quat.identity(*batch, skeleton.num_joints))

    def copy(self) -> Pose:
        """A deep copy, so systems can write without aliasing an asset."""
        return Pose(
            self.root.copy(),
            self.rotations.copy(),
            None if self.offsets is None else self.offsets.copy(),
            None if self.scales is None else self.scales.copy(),
        )

    @property
    def num_joints(self) -> int:
        """Number of joints."""
        return int(self.rotations.shape[-2])

    def is_finite(self) -> bool:
        """False when any value is NaN or infinite (a bad solver or input)."""
        return bool(np.isfinite(self.root).all() and np.isfinite(self.rotations).all())
