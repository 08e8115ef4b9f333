"""Animation ⇄ ragdoll pose blending (PuppetMaster's *mapping weight*).

The final pose of a puppet with a ragdoll is ``blend_poses(animated, simulated, w)``:
``w = 0`` shows the animation, ``w = 1`` the physics. Roots interpolate linearly and
local rotations by slerp, joint by joint, batched over any leading axes like every pose
operation in the engine.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from engine import quat
from engine.pose import Pose

__all__ = ["blend_poses", "blend_rows", "max_rotation_jump"]


def blend_poses(animated: Pose, simulated: Pose, weight: float | ArrayLike) -> Pose:
    """Pose ``weight`` of the way from ``animated`` to ``simulated``.

    Args:
        animated: the animation's pose.
        simulated: the ragdoll's pose on the same skeleton.
        weight: scalar, or per-joint ``[...,J]`` weights (the root position uses joint 0's).
    """
    if animated.rotations.shape != simulated.rotations.shape:
        raise ValueError(f"poses differ in shape: {animated.rotations.shape} vs {simulated.rotations.shape}")
    w = np.clip(np.asarray(weight, dtype=np.float64), 0.0, 1.0)
    if w.ndim == 0:
        if w == 0.0:
            return animated.copy()
        if w == 1.0:
            return simulated.copy()
        w_root, w_rot = w, w
    else:
        w_root, w_rot = w[..., :1], w
    root = animated.root + w_root * (simulated.root - animated.root)
    rot = quat.slerp(animated.rotations, simulated.rotations, w_rot)
    return Pose(root, quat.normalize(rot))


def blend_rows(
    root: NDArray[np.float64],
    rot: NDArray[np.float64],
    sim_root: NDArray[np.float64],
    sim_rot: NDArray[np.float64],
    weight: NDArray[np.float64],
    sizes: NDArray[np.int64],
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """:func:`blend_poses` of many poses at once, each with its own scalar weight: roots ``[n,3]``,
    rotations end to end ``[ΣJ,4]`` (pose ``i`` has ``sizes[i]`` joints), ``weight [n]``. Every number
    is the one :func:`blend_poses` gives for that pose alone (weights 0 and 1 copy exactly)."""
    w = np.clip(np.asarray(weight, dtype=np.float64), 0.0, 1.0)
    per_joint = np.repeat(w, sizes)
    out_root = np.where((w == 1.0)[:, None], sim_root, root)
    out_rot = np.where((per_joint == 1.0)[:, None], sim_rot, rot)
    mid = (w > 0.0) & (w < 1.0)
    if mid.any():
        jm = np.repeat(mid, sizes)
        out_root[mid] = root[mid] + w[mid, None] * (sim_root[mid] - root[mid])
        out_rot[jm] = quat.normalize(quat.slerp(rot[jm], sim_rot[jm], per_joint[jm]))
    return out_root, out_rot


def max_rotation_jump(rotations: ArrayLike) -> float:
    """Largest rotation (rad) any joint makes between consecutive frames of ``[F,J,4]`` rotations.

    The measure of a *pop*: a transition is smooth when its largest per-frame jump stays
    under the largest one the target clip makes on its own.
    """
    rot = np.asarray(rotations, dtype=np.float64)
    if rot.shape[0] < 2:
        return 0.0
    return float(np.max(quat.angle_between(rot[1:], rot[:-1])))
