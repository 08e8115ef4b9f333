"""Stitching (paper §4): spread the gap between the ends of the average cycle over the loop.

For vector values ``c(t) ← c(t) + (t/T − ½)·d_ex`` with ``d_ex = c(0) − c(T)``, so both ends
meet half way and the loop closes exactly while every sample moves by at most half
the gap. A travelling column keeps its per-cycle travel ``τ``: the target is
``c(T) = c(0) + τ``, i.e. ``d_ex = c(0) + τ − c(T)``.

Quaternions are stitched in the tangent space, which is what "the same formula on
the sphere" means: with ``r = log(c(0) · c(T)⁻¹)`` the rotation that carries the end onto
the start, ``c(t) ← exp((t/T − ½)·r) · c(t)``. Both ends land on the same rotation, and the
correction grows linearly in angle, never by raw component arithmetic that would
leave the unit sphere.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from authoring.cycles.trajectory import Trajectory
from engine import quat

__all__ = ["closure_error", "loop_gap", "rotation_angle", "stitch"]


def _ramp(phases: NDArray[np.float64]) -> NDArray[np.float64]:
    return (phases - 0.5)[:, None]


def loop_gap(traj: Trajectory, curve: NDArray[np.float64], travel: NDArray[np.float64]) -> NDArray[np.float64]:
    """Per-column ``d_ex``; for quaternion items the rotation vector ``r`` (in its first three columns, 0 in the fourth)."""
    gap = curve[0] + travel - curve[-1]
    for it in traj.items:
        if it.kind == "rotation":
            c = it.columns
            r = quat.log(quat.mul(curve[0, c], quat.conjugate(curve[-1, c])))
            gap[c] = np.concatenate([r, [0.0]])
    return gap


def stitch(
    traj: Trajectory, curve: NDArray[np.float64], phases: NDArray[np.float64], travel: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The stitched curve ``[S+1, N]`` on ``phases`` (0..1) and the gap ``d_ex`` that was spread.

    Args:
        traj: gives the item kinds.
        curve: the average cycle, first and last rows at phases 0 and 1.
        phases: ``[S+1]`` normalised times ``t/T``.
        travel: ``[N]`` per-cycle travel to keep (zero except for travelling positions).
    """
    gap = loop_gap(traj, curve, travel)
    out = curve + _ramp(phases) * gap
    for it in traj.items:
        if it.kind == "rotation":
            c = it.columns
            corr = quat.exp(_ramp(phases) * gap[c][:3])
            out[:, c] = quat.normalize(quat.mul(corr, curve[:, c]))
    return out, gap


def rotation_angle(a: NDArray[np.float64], b: NDArray[np.float64]) -> float:
    """Angle in radians between two rotations, accurate near zero (``arccos`` is not)."""
    rel = quat.mul(quat.conjugate(a), b)
    return float(np.max(2.0 * np.arctan2(np.linalg.norm(rel[..., 1:], axis=-1), np.abs(rel[..., 0]))))


def closure_error(traj: Trajectory, loop_closed: NDArray[np.float64], travel: NDArray[np.float64]) -> float:
    """Largest mismatch between the loop's end (phase 1) and its start plus travel.

    Vector columns in their own units, quaternion items as an angle in radians.
    """
    err = np.abs(loop_closed[-1] - travel - loop_closed[0])
    worst = 0.0
    rot_cols = np.zeros(traj.dims, dtype=bool)
    for it in traj.items:
        if it.kind == "rotation":
            rot_cols[it.columns] = True
            worst = max(worst, rotation_angle(loop_closed[0, it.columns], loop_closed[-1, it.columns]))
    if np.any(~rot_cols):
        worst = max(worst, float(err[~rot_cols].max()))
    return worst
