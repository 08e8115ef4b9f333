"""Analytic Jacobians of points and orientations with respect to the rig coordinates.

Thesis Eq. 4.2: for a rotational attribute, ``∂s_P/∂c_i = v × (s_P − r)`` and
``∂s_O/∂c_i = v``, where ``v`` is the world rotation axis of the attribute and ``r``
its centre; for a translation, ``∂s_P/∂c_i = v``. Everything here is that formula
batched over all coordinates and all points at once.

For a ball joint the coordinate is a rotation vector ``φ``, and the axis of each of
its three components is not simply a world basis vector: perturbing ``φ`` by ``dφ``
turns the joint by ``J_r(φ)·dφ`` in its own frame, where ``J_r`` is the right
Jacobian of SO(3). So the world axes of a ball joint are the columns of
``R_world(joint) · J_r(φ)``. A hinge's axis is its local axis seen in the world.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from engine.ik._vec import cross
from engine.ik.rig import BALL, IKRig

__all__ = ["right_jacobian", "ball_axis_columns", "dof_axes", "point_jacobian", "orientation_jacobian"]

from engine.arrays import F64 as F


def _skew(v: F) -> F:
    """``[...,3,3]`` cross-product matrices of ``v [...,3]``."""
    z = np.zeros(v.shape[:-1])
    x, y, w = v[..., 0], v[..., 1], v[..., 2]
    return np.stack([np.stack([z, -w, y], -1), np.stack([w, z, -x], -1), np.stack([-y, x, z], -1)], -2)


def right_jacobian(phi: ArrayLike) -> F:
    """``[...,3,3]`` right Jacobian of SO(3): ``exp(φ + dφ) ≈ exp(φ)·exp(J_r(φ) dφ)``.

    ``J_r = I − (1−cos θ)/θ² [φ]× + (θ − sin θ)/θ³ [φ]×²``, with Taylor limits near
    ``θ = 0`` so the identity pose is exact.
    """
    phi = np.asarray(phi, dtype=np.float64)
    th = np.linalg.norm(phi, axis=-1)
    small = th < 1e-4
    ths = np.where(small, 1.0, th)
    a = np.where(small, 0.5 - th**2 / 24.0, (1.0 - np.cos(ths)) / ths**2)
    b = np.where(small, 1.0 / 6.0 - th**2 / 120.0, (ths - np.sin(ths)) / ths**3)
    k = _skew(phi)
    eye = np.broadcast_to(np.eye(3), k.shape)
    return eye - a[..., None, None] * k + b[..., None, None] * (k @ k)


def ball_axis_columns(phi: F, slot: NDArray[np.int64]) -> F:
    """Column ``slot`` of the right Jacobian ``J_r(φ)`` of rotation vectors ``phi [...,3]``: ``[...,3]``.

    ``J_r(φ) = I − a[φ]× + b[φ]×²`` with ``[φ]×² = φφᵀ − θ²I``, taken column by column
    without building matrices (the IK's and the tangent solver's inner loops call it for
    every ball joint at every sample time); ``slot`` broadcasts against ``phi.shape[:-1]``.
    Near θ = 0 the coefficients use their series, so the columns stay exact.
    """
    th2 = np.einsum("...i,...i->...", phi, phi)
    th = np.sqrt(th2)
    small = th < 1e-4
    ths = np.where(small, 1.0, th)
    a = np.where(small, 0.5 - th2 / 24.0, (1.0 - np.cos(ths)) / ths**2)
    b = np.where(small, 1.0 / 6.0 - th2 / 120.0, (ths - np.sin(ths)) / ths**3)
    slot = np.broadcast_to(slot, phi.shape[:-1])
    e = (slot[..., None] == np.arange(3)).astype(np.float64)
    phis = np.take_along_axis(phi, slot[..., None], axis=-1)[..., 0]
    return e * (1.0 - b * th2)[..., None] - a[..., None] * cross(phi, e) + (b * phis)[..., None] * phi


def dof_axes(rig: IKRig, c: ArrayLike, wmat: ArrayLike) -> F:
    """``[K,3]`` world axis of every coordinate (rotation axis, or translation direction).

    Args:
        rig: the layout.
        c: ``[K]`` current coordinates.
        wmat: ``[J,3,3]`` world rotation matrices from FK of the pose built from ``c``.
    """
    c = np.asarray(c, dtype=np.float64)
    wmat = np.asarray(wmat, dtype=np.float64)
    rv = rig.rotation_vectors(c)
    local = np.zeros((rig.num_dofs, 3))
    t = rig.dof_translation
    local[t, rig.dof_slot[t]] = 1.0
    r = ~t
    j, s = rig.dof_joint[r], rig.dof_slot[r]
    ball = rig.kinds[j] == BALL
    col = ball_axis_columns(rv[j[ball]], s[ball])
    rows = np.zeros((int(r.sum()), 3))
    rows[ball] = col
    rows[~ball] = rig.axes[j[~ball]]
    local[r] = np.einsum("nij,nj->ni", wmat[j], rows)
    return local


def point_jacobian(
    rig: IKRig,
    axes: ArrayLike,
    wpos: ArrayLike,
    frames: ArrayLike,
    points: ArrayLike,
    columns: ArrayLike | None = None,
) -> F:
    """``[3P, K']`` Jacobian of world points attached to joints ``frames [P]``.

    Args:
        axes: ``[K,3]`` from :func:`dof_axes`.
        wpos: ``[J,3]`` world joint positions.
        frames: ``[P]`` joint each point rides on.
        points: ``[P,3]`` the points' world positions.
        columns: optional coordinate indices to keep (the reduced problem of §4.2.3).
    """
    axes = np.asarray(axes)
    frames = np.asarray(frames, dtype=np.int64)
    cols = np.arange(rig.num_dofs) if columns is None else np.asarray(columns, dtype=np.int64)
    ax = axes[cols]
    centre = np.asarray(wpos)[rig.dof_joint[cols]]
    lever = np.asarray(points)[:, None, :] - centre[None]  # [P,K',3]
    blocks = cross(ax[None], lever)
    trans = rig.dof_translation[cols]
    blocks[:, trans] = ax[trans][None]
    blocks *= rig.ancestors[frames][:, rig.dof_joint[cols]][..., None]
    return blocks.transpose(0, 2, 1).reshape(-1, cols.size)


def orientation_jacobian(rig: IKRig, axes: ArrayLike, frames: ArrayLike, columns: ArrayLike | None = None) -> F:
    """``[3P, K']`` Jacobian of the world angular velocity of joints ``frames [P]``."""
    frames = np.asarray(frames, dtype=np.int64)
    cols = np.arange(rig.num_dofs) if columns is None else np.asarray(columns, dtype=np.int64)
    ax = np.asarray(axes)[cols]
    mask = rig.ancestors[frames][:, rig.dof_joint[cols]] & ~rig.dof_translation[cols][None]
    blocks = ax[None] * mask[..., None]
    return blocks.transpose(0, 2, 1).reshape(-1, cols.size)
