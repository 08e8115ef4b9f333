"""MoCurves of a clip: one per animated item, with keypoints, arrows and φ (SCA 2017 §5.1).

An *item* is a joint of the clip's skeleton. Its MoCurve is what the viewport shows:

- ``positions [F,3]`` — the trajectory γ_P sampled at every frame (the keypoints), in the
  character's space (root motion removed, so a walk's feet draw closed loops);
- ``rotations [F,4]`` and ``scales [F]`` — the two orthogonal arrows at every keypoint,
  whose directions show the orientation and lengths show the scale (Fig. 3);
- ``times [F]`` — φ: keypoint ``k`` is the item at ``t = k/fps``; a point anywhere on the
  closed curve maps to a time by :meth:`MoCurve.time_at`, one correspondence shared by
  position, rotation and scale (they are sampled at the same keypoints).

Which channels an item owns decides what an edit of it changes: the root owns the root
position and the root rotation; a joint two links below a non-root joint (hands, feet, head)
is *positionable* — its position is reached by two-bone IK on (grandparent, parent, joint);
every joint owns its local rotation.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from engine import quat
from engine.clip import Clip
from engine.fk import forward_kinematics
from engine.skeleton import Skeleton

__all__ = ["MoCurve", "mocurves", "item_chain", "layer_joints", "LAYERS", "ARROW_AXES"]

from engine.arrays import F64 as F

LAYERS = ("item", "limb", "all")
"""Layer choices for time warps: the item's own joint, the limb it ends (the IK chain), every joint."""

ARROW_AXES = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0]])
"""Local axes drawn as the two orthogonal arrows: forward (+Z) and up (+Y)."""


@dataclass(frozen=True)
class MoCurve:
    """One item's curve over a cycle, sampled at its keypoints (one per frame).

    Attributes:
        item: joint name.
        joint: joint index.
        fps: keypoints per second.
        positions: ``[F,3]`` keypoint positions, character space.
        rotations: ``[F,4]`` world (character-space) orientation at each keypoint.
        scales: ``[F]`` scale at each keypoint.
    """

    item: str
    joint: int
    fps: float
    positions: F
    rotations: F
    scales: F

    @property
    def num_keypoints(self) -> int:
        """Keypoints per cycle ``F``."""
        return len(self.positions)

    @property
    def period(self) -> float:
        """Cycle length in seconds."""
        return self.num_keypoints / self.fps

    @property
    def times(self) -> F:
        """φ at the keypoints: ``k / fps``."""
        return np.arange(self.num_keypoints) / self.fps

    def arrows(self, length: float = 0.08) -> tuple[F, F]:
        """Tips of the two arrows ``[F,2,3]`` and their base points ``[F,3]``; length scales with ``scales``."""
        axes = quat.rotate(self.rotations[:, None, :], ARROW_AXES[None])  # [F,2,3]
        tips = self.positions[:, None, :] + axes * (length * self.scales)[:, None, None]
        return tips, self.positions

    def speeds(self) -> F:
        """``[F]`` speed (m/s) leaving each keypoint, across the seam too: what the spacing shows."""
        d = np.roll(self.positions, -1, axis=0) - self.positions
        return np.linalg.norm(d, axis=1) * self.fps

    def closest(self, point: ArrayLike) -> tuple[float, float]:
        """``(φ(s), distance)`` of the point of the closed keypoint polyline nearest ``point``.

        The curve parameter maps to time linearly within a segment, so a keypoint dragged
        half-way between keypoints 3 and 4 asks for the time 3.5/fps.
        """
        p = np.asarray(point, dtype=np.float64)
        a = self.positions
        d = np.roll(a, -1, axis=0) - a
        length2 = np.maximum(np.sum(d * d, axis=1), 1e-18)
        u = np.clip(np.sum((p - a) * d, axis=1) / length2, 0.0, 1.0)
        dist = np.linalg.norm(a + u[:, None] * d - p, axis=1)
        k = int(np.argmin(dist))
        return float((k + u[k]) / self.fps), float(dist[k])

    def time_at(self, point: ArrayLike) -> float:
        """φ of the curve point nearest ``point`` (seconds in ``[0, period)``)."""
        return self.closest(point)[0]

    def position_at(self, t: float) -> F:
        """γ_P(φ⁻¹(t)): the point of the keypoint polyline at time ``t`` (wrapped)."""
        f = float(np.mod(t * self.fps, self.num_keypoints))
        k = int(np.floor(f)) % self.num_keypoints
        a, b = self.positions[k], self.positions[(k + 1) % self.num_keypoints]
        return a + (f - np.floor(f)) * (b - a)


def item_chain(skeleton: Skeleton, joint: int) -> tuple[int, int, int] | None:
    """The two-bone chain (grandparent, parent, joint) that positions ``joint``, or ``None``.

    The root is positioned directly and has no chain; a joint whose grandparent is the root
    (or missing) would move the hips to reach, so it is not positionable.
    """
    p = int(skeleton.parents[joint])
    if p < 0:
        return None
    g = int(skeleton.parents[p])
    if g <= 0:
        return None
    return g, p, joint


def layer_joints(skeleton: Skeleton, joint: int, layer: str) -> tuple[int, ...]:
    """The joints a time warp of item ``joint`` retimes under ``layer`` (see :data:`LAYERS`)."""
    if layer == "all":
        return tuple(range(skeleton.num_joints))
    if layer == "limb":
        chain = item_chain(skeleton, joint)
        return tuple(chain) if chain is not None else (joint,)
    if layer == "item":
        return (joint,)
    raise ValueError(f"unknown layer {layer!r}; choose one of {', '.join(LAYERS)}")


def mocurves(clip: Clip, scales: ArrayLike | None = None) -> dict[str, MoCurve]:
    """Every item's MoCurve of ``clip`` (character space), keyed by joint name.

    Args:
        clip: the cycle being edited.
        scales: ``[F,J]`` per-joint scale tracks (ones when omitted).
    """
    sk = clip.skeleton
    pos, rot = forward_kinematics(sk, clip.root, clip.rotations)
    s = np.ones((clip.num_frames, sk.num_joints)) if scales is None else np.asarray(scales, dtype=np.float64)
    if s.shape != (clip.num_frames, sk.num_joints):
        raise ValueError(f"scales must be [{clip.num_frames},{sk.num_joints}], got {s.shape}")
    return {
        name: MoCurve(name, j, clip.fps, pos[:, j].copy(), rot[:, j].copy(), s[:, j].copy())
        for j, name in enumerate(sk.names)
    }
