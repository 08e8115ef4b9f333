"""Float kernels for one pose: 3-vectors and quaternions as tuples, and a root-to-joint FK walk.

The per-frame IK of one puppet (two legs, two arms, a few re-measures of the
shoulders while the spine leans) works on a handful of 3-vectors at a time. At
that size every numpy call costs about a microsecond of dispatch for a few
nanoseconds of arithmetic, so the stage spent 10 ms per puppet in overhead. The
same formulas written on Python floats cost a tenth of a microsecond per
component. Each kernel here repeats the arithmetic of its batched counterpart in
:mod:`engine.quat` / :mod:`engine.ik._vec` operation for operation, so a limb
solved here agrees with the batched solver to rounding.

Vectors are ``(x, y, z)`` tuples, quaternions ``(w, x, y, z)`` tuples.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from functools import lru_cache
from typing import cast

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "V",
    "Q",
    "Q_ID",
    "add",
    "sub",
    "scale",
    "dot",
    "cross",
    "norm",
    "unit",
    "qmul",
    "qconj",
    "qnormalize",
    "qrot",
    "from_axis_angle",
    "between",
    "slerp",
    "from_frames",
    "path_of",
    "chain_fk",
    "as_q",
]

V = tuple[float, float, float]
Q = tuple[float, float, float, float]
Q_ID: Q = (1.0, 0.0, 0.0, 0.0)


def add(a: V, b: V) -> V:
    """``a + b``."""
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def sub(a: V, b: V) -> V:
    """``a − b``."""
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def scale(s: float, a: V) -> V:
    """``s · a``."""
    return (s * a[0], s * a[1], s * a[2])


def dot(a: V, b: V) -> float:
    """``a · b``, summed x, y, z in that order like numpy's."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a: V, b: V) -> V:
    """``a × b``."""
    ax, ay, az = a
    bx, by, bz = b
    return (ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx)


def norm(a: V) -> float:
    """``|a|``, as ``np.linalg.norm`` over the last axis."""
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


def unit(a: V, eps: float) -> V:
    """``a / max(|a|, eps)``, as the batched solvers' ``_unit``."""
    n = max(norm(a), eps)
    return (a[0] / n, a[1] / n, a[2] / n)


def qmul(a: Q, b: Q) -> Q:
    """Hamilton product ``a * b`` (:func:`engine.quat.mul`)."""
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    )


def qconj(q: Q) -> Q:
    """Conjugate: the inverse of a unit quaternion."""
    return (q[0], -q[1], -q[2], -q[3])


def qnormalize(q: Q) -> Q:
    """Unit quaternion; a zero one becomes the identity (:func:`engine.quat.normalize`)."""
    n = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    if n > 1e-12:
        return (q[0] / n, q[1] / n, q[2] / n, q[3] / n)
    return Q_ID


def qrot(q: Q, v: V) -> V:
    """Rotate ``v`` by the unit quaternion ``q``: ``v + 2w(u×v) + u×(2u×v)``."""
    w, x, y, z = q
    vx, vy, vz = v
    tx = 2.0 * (y * vz - z * vy)
    ty = 2.0 * (z * vx - x * vz)
    tz = 2.0 * (x * vy - y * vx)
    return (vx + w * tx + (y * tz - z * ty), vy + w * ty + (z * tx - x * tz), vz + w * tz + (x * ty - y * tx))


def from_axis_angle(axis: V, angle: float) -> Q:
    """Rotation of ``angle`` about ``axis`` (normalised here, a zero axis left as is)."""
    n = norm(axis)
    if not n > 1e-12:
        n = 1.0
    half = 0.5 * angle
    s = math.sin(half)
    return (math.cos(half), s * (axis[0] / n), s * (axis[1] / n), s * (axis[2] / n))


def between(u: V, v: V) -> Q:
    """Shortest-arc rotation taking direction ``u`` to ``v`` (:func:`engine.quat.between`)."""
    nu, nv = norm(u) or math.nan, norm(v) or math.nan  # a zero direction gives NaN, as in numpy
    u = (u[0] / nu, u[1] / nu, u[2] / nu)
    v = (v[0] / nv, v[1] / nv, v[2] / nv)
    d = dot(u, v)
    if 1.0 + d < 1e-9:  # opposite: any axis perpendicular to u
        perp = cross(u, (1.0, 0.0, 0.0))
        if norm(perp) < 1e-6:
            perp = cross(u, (0.0, 1.0, 0.0))
        return qnormalize((0.0, *perp))
    return qnormalize((1.0 + d, *cross(u, v)))


def slerp(a: Q, b: Q, t: float) -> Q:
    """Spherical interpolation along the shorter arc (:func:`engine.quat.slerp`)."""
    if a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3] < 0.0:
        b = (-b[0], -b[1], -b[2], -b[3])
    d = min(max(a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3], -1.0), 1.0)
    theta = math.acos(d)
    s = math.sin(theta)
    if s < 1e-6:
        wa, wb = 1.0 - t, t
    else:
        wa, wb = math.sin((1.0 - t) * theta) / s, math.sin(t * theta) / s
    return qnormalize((wa * a[0] + wb * b[0], wa * a[1] + wb * b[1], wa * a[2] + wb * b[2], wa * a[3] + wb * b[3]))


def _frame(a: V, b: V) -> tuple[V, V, V]:
    """Orthonormal columns ``a``, ``b`` (orthogonalised against ``a``) and ``a × b``."""
    a = unit(a, 1e-12)
    d = dot(a, b)
    b = unit((b[0] - d * a[0], b[1] - d * a[1], b[2] - d * a[2]), 1e-12)
    return a, b, cross(a, b)


def from_frames(world: tuple[V, V], local: tuple[V, V]) -> Q:
    """Rotation taking the frame built on ``local`` (two directions) to the one built on ``world``.

    The frames are :func:`_frame` matrices with those columns; the result is
    ``W · Lᵀ`` turned into a quaternion by Shepperd's method, ``w ≥ 0``
    (:func:`engine.quat.from_matrix`).
    """
    wc = _frame(*world)
    lc = _frame(*local)
    # m[i][k] = Σ_j W[i][j] L[k][j]; column j of W is wc[j], so W[i][j] = wc[j][i].
    m = [[wc[0][i] * lc[0][k] + wc[1][i] * lc[1][k] + wc[2][i] * lc[2][k] for k in range(3)] for i in range(3)]
    tr = m[0][0] + m[1][1] + m[2][2]
    diag = (tr, m[0][0], m[1][1], m[2][2])
    best = diag.index(max(diag))
    if best == 0:
        q = (1 + tr, m[2][1] - m[1][2], m[0][2] - m[2][0], m[1][0] - m[0][1])
    elif best == 1:
        q = (m[2][1] - m[1][2], 1 + 2 * m[0][0] - tr, m[0][1] + m[1][0], m[0][2] + m[2][0])
    elif best == 2:
        q = (m[0][2] - m[2][0], m[0][1] + m[1][0], 1 + 2 * m[1][1] - tr, m[1][2] + m[2][1])
    else:
        q = (m[1][0] - m[0][1], m[0][2] + m[2][0], m[1][2] + m[2][1], 1 + 2 * m[2][2] - tr)
    q = qnormalize(q)
    return (-q[0], -q[1], -q[2], -q[3]) if q[0] < 0.0 else q


def as_q(row: Sequence[float]) -> Q:
    """A pose's rotation row (a list from ``ndarray.tolist()``) as a quaternion tuple."""
    w, x, y, z = row
    return (w, x, y, z)


@lru_cache(maxsize=256)
def _path(parents: bytes, joint: int) -> tuple[int, ...]:
    par = np.frombuffer(parents, dtype=np.int64)
    path = [joint]
    while path[-1] != 0:
        path.append(int(par[path[-1]]))
    return tuple(path[::-1])


def path_of(parents: NDArray[np.int64], joint: int) -> tuple[int, ...]:
    """Joints from the root down to ``joint`` (inclusive), cached per hierarchy."""
    return _path(parents.tobytes(), joint)


def chain_fk(
    parents: NDArray[np.int64], root: V, rot: Sequence[Sequence[float]], off: Sequence[Sequence[float]], joint: int
) -> tuple[dict[int, V], dict[int, Q]]:
    """World positions and rotations on the root-to-``joint`` path of one pose.

    ``rot`` and ``off`` are the pose's local rotations and bone offsets as lists of
    tuples (``ndarray.tolist()``), the same walk as :func:`engine.ik._vec.path_fk`.
    """
    path = path_of(parents, joint)
    pos: dict[int, V] = {0: root}
    wr: dict[int, Q] = {0: as_q(rot[0])}
    p = 0
    for j in path[1:]:
        # The rows are read by unpacking only, so a list row serves as well as a tuple (no copy per joint).
        pos[j] = add(pos[p], qrot(wr[p], cast(V, off[j])))
        wr[j] = qmul(wr[p], cast(Q, rot[j]))
        p = j
    return pos, wr
