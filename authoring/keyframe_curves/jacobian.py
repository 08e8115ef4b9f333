"""Batched FK and channel Jacobians of joint points at many times at once (the solver's ``∂s/∂c``).

A drag with pins over a 20-frame interpolation linearises the effector and every held
point at up to ~40 times per iteration. Done one time after another (FK, axes, Jacobian
per sample) that is dozens of small numpy calls each; here all samples go through one
batched pointer-jumping FK (as in :mod:`engine.ik._fk`) and one vectorised Jacobian,
for the channel rigs of keyframed clips: root translation then a rotation vector per
joint, every joint a ball (:func:`authoring.keyframe_curves.solver.curve_rig`).
The formulas are those of :mod:`engine.ik.jacobian` (thesis Eq. 4.2 with the right
Jacobian of SO(3) for rotation vectors).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from engine import quat
from engine.ik._fk import _jumps
from engine.ik._vec import cross
from engine.ik.jacobian import ball_axis_columns
from engine.ik.rig import IKRig

__all__ = ["batch_points"]

from engine.arrays import F64 as F


def _fk(rig: IKRig, c: F) -> tuple[F, F]:
    """``(wpos [T,J,3], wmat [T,J,3,3])`` of channel rows ``c [T,3+3J]``."""
    sk = rig.skeleton
    n = sk.num_joints
    t_count = c.shape[0]
    m = np.zeros((t_count, n + 1, 4, 4))
    m[:, :n, :3, :3] = quat.to_matrix(quat.exp(c[:, 3:].reshape(t_count, n, 3)))
    m[:, :n, :3, 3] = sk.offsets
    m[:, 0, :3, 3] = c[:, :3]
    m[:, :, 3, 3] = 1.0
    m[:, n, :3, :3] = np.eye(3)
    for anc in _jumps(sk):
        m = m[:, anc] @ m
    return m[:, :n, :3, 3], m[:, :n, :3, :3]


def batch_points(rig: IKRig, c: F, joints: NDArray[np.int64], points: F, cols: NDArray[np.int64],
                 rot_joint: int | None = None) -> tuple[F, F, F | None, F | None]:  # fmt: skip
    """World points and their channel Jacobians at ``T`` times.

    Args:
        rig: an all-ball channel rig with root translation (``3 + 3J`` coordinates).
        c: ``[T,C]`` channel values, one row per time.
        joints: ``[T]`` the joint each row's point rides on; points: ``[T,3]`` local points.
        cols: ``[C']`` channels to differentiate by.
        rot_joint: when given, also the world orientation of that joint at row 0 and its Jacobian.

    Returns:
        ``(pos [T,3], jac [T,3,C'], rot [4] | None, rot_jac [3,C'] | None)``.
    """
    wpos, wmat = _fk(rig, c)
    rows = np.arange(c.shape[0])
    pos = wpos[rows, joints] + np.einsum("tij,tj->ti", wmat[rows, joints], points)
    trans = rig.dof_translation[cols]
    dj = rig.dof_joint[cols]
    slot = rig.dof_slot[cols]
    # World axis of every channel at every time: R_world(parent frame of the joint) · J_r(φ)[:, s].
    phi = c[:, 3:].reshape(c.shape[0], -1, 3)[:, dj]  # [T,C',3]
    local = ball_axis_columns(phi, slot)
    axes = np.einsum("tkij,tkj->tki", wmat[:, dj], local)
    axes[:, trans] = np.eye(3)[slot[trans]][None]
    lever = pos[:, None, :] - wpos[:, dj]
    jac = cross(axes, lever)
    jac[:, trans] = axes[:, trans]
    jac *= rig.ancestors[joints][:, dj][..., None]
    jac = jac.transpose(0, 2, 1)
    rot = rot_jac = None
    if rot_joint is not None:
        rot = quat.from_matrix(wmat[0, rot_joint])
        mask = rig.ancestors[rot_joint][dj] & ~trans
        rot_jac = (axes[0] * mask[:, None]).T
    return pos, jac, rot, rot_jac
