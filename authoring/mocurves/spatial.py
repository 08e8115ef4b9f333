"""Spatial MoCurve edits (SCA 2017 §5.1, Fig. 3): control points, arrow rotation, arrow scale.

- **Control points.** γ_P is shown with the control points of a closed uniform cubic
  B-spline fitted (least squares) to the keypoints. Dragging control point ``k`` by ``Δ``
  moves every keypoint by ``B[:,k]·Δ`` — exactly how the fitted spline moves — while the
  residual detail the spline does not capture rides along unchanged. The root's position
  is written straight into the clip; any other positionable item is reached per frame by
  two-bone IK on its chain, with its orientation kept.
- **Arrows.** Rotating the arrows of keypoint ``i`` by ``dθ`` (a world rotation vector) or
  scaling them by ``ds`` (a log-scale step) propagates to keypoints ``j`` in ``[i−τ, i+τ]``
  with the Gaussian weight ``exp(−σ(i−j)²)`` — wrapping around the loop, since a cycle has
  no ends. The weights are what the viewport highlights in red.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import ArrayLike

from authoring.mocurves.curves import item_chain
from engine import quat
from engine.clip import Clip
from engine.fk import forward_kinematics
from engine.ik import two_bone_ik
from engine.pose import Pose
from engine.root_curve import closed_basis

__all__ = [
    "gaussian_weights",
    "rotate_arrow",
    "scale_arrow",
    "control_basis",
    "control_points",
    "move_control_point",
    "set_positions",
]

from engine.arrays import F64 as F


def gaussian_weights(n: int, i: int, tau: int, sigma: float) -> F:
    """``[n]`` weights ``exp(−σ(i−j)²)`` for ``j ∈ [i−τ, i+τ]`` (cyclic), zero elsewhere.

    ``τ`` is clamped to ``(n−1)//2`` so the window never wraps onto itself.
    """
    if not 0 <= i < n:
        raise ValueError(f"keypoint {i} is outside 0…{n - 1}")
    if tau < 0 or sigma < 0 or not np.isfinite(sigma):
        raise ValueError(f"τ and σ must be non-negative, got τ={tau}, σ={sigma}")
    tau = min(int(tau), (n - 1) // 2)
    w = np.zeros(n)
    offsets = np.arange(-tau, tau + 1)
    w[(i + offsets) % n] = np.exp(-sigma * offsets.astype(np.float64) ** 2)
    return w


def rotate_arrow(clip: Clip, joint: int, i: int, dtheta: ArrayLike, tau: int, sigma: float) -> Clip:
    """Turn item ``joint``'s orientation at keypoint ``i`` by the world rotation vector ``dθ``, with falloff.

    Keypoint ``j`` turns by ``exp(−σ(i−j)²)·dθ`` about the same world axis; the joint's
    children follow as a rigid body would.
    """
    d = np.asarray(dtheta, dtype=np.float64)
    if d.shape != (3,) or not np.all(np.isfinite(d)):
        raise ValueError(f"dθ must be a finite rotation vector [3], got {dtheta!r}")
    w = gaussian_weights(clip.num_frames, i, tau, sigma)
    frames = np.flatnonzero(w)
    _, wrot = forward_kinematics(clip.skeleton, clip.root, clip.rotations)
    p = int(clip.skeleton.parents[joint])
    parent = wrot[frames, p] if p >= 0 else quat.identity(len(frames))
    turn = quat.exp(w[frames, None] * d[None])
    # World W' = turn·W with W = parent·L, so L' = parent⁻¹·turn·parent·L.
    local = quat.mul(quat.conjugate(parent), quat.mul(turn, quat.mul(parent, clip.rotations[frames, joint])))
    rot = clip.rotations.copy()
    rot[frames, joint] = quat.normalize(local)
    return replace(clip, rotations=rot)


def scale_arrow(scales: ArrayLike, joint: int, i: int, ds: float, tau: int, sigma: float) -> F:
    """Scale tracks ``[F,J]`` with item ``joint`` scaled by ``exp(w_j·ds)`` around keypoint ``i``."""
    s = np.array(scales, dtype=np.float64)
    if not np.isfinite(ds):
        raise ValueError(f"scale step must be finite, got {ds}")
    w = gaussian_weights(len(s), i, tau, sigma)
    s[:, joint] = s[:, joint] * np.exp(w * float(ds))
    return s


def control_basis(n: int, k: int) -> F:
    """``[n,k]`` closed uniform cubic B-spline basis at the ``n`` keypoints (partition of unity).

    The engine's (:func:`engine.root_curve.closed_basis`), so the extractor's root curve and
    MoCurves' own control points index alike.
    """
    return closed_basis(n, k)


def control_points(positions: ArrayLike, k: int) -> F:
    """``[k,3]`` least-squares control points of the closed B-spline through the keypoints."""
    p = np.asarray(positions, dtype=np.float64)
    b = control_basis(len(p), k)
    return np.asarray(np.linalg.solve(b.T @ b, b.T @ p), dtype=np.float64)


def set_positions(clip: Clip, joint: int, positions: ArrayLike) -> Clip:
    """``clip`` with item ``joint`` at ``positions [F,3]`` (character space), orientation kept.

    The root is moved directly; other positionable joints by two-bone IK per frame.

    Raises:
        ValueError: the item's position is not editable (it follows its parents).
    """
    target = np.asarray(positions, dtype=np.float64)
    if target.shape != (clip.num_frames, 3) or not np.all(np.isfinite(target)):
        raise ValueError(f"positions must be finite [{clip.num_frames},3]")
    sk = clip.skeleton
    if joint == 0:
        return replace(clip, root=target)
    chain = item_chain(sk, joint)
    if chain is None:
        raise ValueError(f"{sk.names[joint]}'s position follows its parents; edit its rotation instead")
    _, wrot = forward_kinematics(sk, clip.root, clip.rotations)
    pose = Pose(clip.root.copy(), clip.rotations.copy())
    two_bone_ik(sk, pose, chain, target, end_rotation=wrot[:, joint])
    return replace(clip, rotations=pose.rotations)


def move_control_point(clip: Clip, joint: int, positions: ArrayLike, k: int, index: int, delta: ArrayLike) -> Clip:
    """Drag control point ``index`` of ``k`` by ``delta`` on the curve through ``positions [F,3]``."""
    d = np.asarray(delta, dtype=np.float64)
    if d.shape != (3,) or not np.all(np.isfinite(d)):
        raise ValueError(f"delta must be a finite [3], got {delta!r}")
    p = np.asarray(positions, dtype=np.float64)
    b = control_basis(len(p), k)
    if not 0 <= index < k:
        raise ValueError(f"control point {index} is outside 0…{k - 1}")
    return set_positions(clip, joint, p + b[:, index, None] * d[None])
