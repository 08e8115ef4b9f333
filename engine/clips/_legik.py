"""Analytic two-bone leg IK used at authoring time (hip → knee → ankle, knee towards a pole).

The clips are authored as *intent*: where each ankle is and how the foot is oriented in
the world. This solver turns that into local joint rotations exactly, so a stance foot
keyed to stay put stays put in the sampled clip. It is deliberately small and specific to
the authoring of the default clips (bones along −Y in the rest pose, knee as a hinge about
the thigh's local X); the runtime IK with pins and limits lives in ``engine/ik``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from engine import quat
from engine.arrays import F64 as F

__all__ = ["LegSolution", "solve_leg"]


@dataclass(frozen=True)
class LegSolution:
    """Local rotations ``[N,4]`` of thigh, knee and foot, and how far the leg was stretched.

    ``reach`` is |hip→ankle| / (thigh + shin) before clamping: above ``max_reach`` the
    ankle could not be reached and the foot was left short of its target.
    """

    upper: F
    knee: F
    foot: F
    reach: F
    knee_flex: F


def _unit(v: F, fallback: F) -> F:
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return np.where(n > 1e-9, v / np.where(n > 1e-9, n, 1.0), fallback)


def solve_leg(
    hip: F,
    parent_rot: F,
    ankle: F,
    pole: F,
    foot_rot: F,
    thigh: float,
    shin: float,
    max_reach: float = 0.9995,
) -> LegSolution:
    """Solve one leg for ``N`` frames at once.

    Args:
        hip: ``[N,3]`` world position of the hip joint (top of the thigh).
        parent_rot: ``[N,4]`` world rotation of the pelvis (the thigh's parent).
        ankle: ``[N,3]`` world target of the ankle (the foot joint).
        pole: ``[N,3]`` direction the knee should point to (forward for a standing leg).
        foot_rot: ``[N,4]`` desired world rotation of the foot.
        thigh: hip-to-knee length; shin: knee-to-ankle length.
        max_reach: fraction of the full leg length the solver may stretch to; keeping it
            below 1 keeps the knee's bend direction defined.

    Returns:
        The local rotations that put the ankle on its target (when reachable), bend the
        knee forward only (flexion ≥ 0), and give the foot its world rotation.
    """
    d_vec = ankle - hip
    d = np.linalg.norm(d_vec, axis=-1)
    reach = d / (thigh + shin)
    dc = np.clip(d, abs(thigh - shin) + 1e-6, (thigh + shin) * max_reach)
    u = _unit(d_vec, np.array([0.0, -1.0, 0.0]))
    w = pole - np.sum(pole * u, axis=-1, keepdims=True) * u
    w = _unit(w, np.array([0.0, 0.0, 1.0]))
    cos_b = np.clip((thigh**2 + dc**2 - shin**2) / (2 * thigh * dc), -1.0, 1.0)
    sin_b = np.sqrt(1.0 - cos_b**2)
    t = cos_b[:, None] * u + sin_b[:, None] * w  # thigh direction, hip -> knee
    z = -sin_b[:, None] * u + cos_b[:, None] * w  # thigh's forward axis, towards the pole
    y = -t
    x = np.cross(y, z)
    upper_world = quat.from_matrix(np.stack([x, y, z], axis=-1))
    cos_g = np.clip((thigh**2 + shin**2 - dc**2) / (2 * thigh * shin), -1.0, 1.0)
    flex = np.pi - np.arccos(cos_g)
    knee = quat.from_axis_angle(np.array([1.0, 0.0, 0.0]), flex)
    upper = quat.mul(quat.conjugate(parent_rot), upper_world)
    shin_world = quat.mul(upper_world, knee)
    foot = quat.mul(quat.conjugate(shin_world), foot_rot)
    return LegSolution(upper, knee, foot, reach, flex)
