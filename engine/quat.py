"""Quaternion helpers over numpy arrays, batched over any leading dimensions.

Convention: quaternions are ``(w, x, y, z)`` (scalar first), as MuJoCo and glTF's
maths texts write them; scipy's ``Rotation`` is scalar last, so convert at that
boundary only. Every function accepts arrays of shape ``[..., 4]`` (and ``[..., 3]``
for vectors) so that one call handles all joints of all puppets: per-joint Python
loops are never on the hot path.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from engine.arrays import F64 as F

__all__ = [
    "IDENTITY",
    "identity",
    "normalize",
    "mul",
    "conjugate",
    "rotate",
    "from_axis_angle",
    "to_axis_angle",
    "log",
    "exp",
    "slerp",
    "nlerp",
    "align_hemisphere",
    "to_matrix",
    "from_matrix",
    "from_euler",
    "to_euler",
    "between",
    "swing_twist",
    "angle_between",
    "from_xyzw",
    "to_xyzw",
]

IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])


def identity(*shape: int) -> F:
    """Identity quaternions of shape ``[*shape, 4]``."""
    q = np.zeros((*shape, 4))
    q[..., 0] = 1.0
    return q


def normalize(q: ArrayLike) -> F:
    """Unit quaternions; a zero quaternion becomes the identity rather than NaN."""
    q = np.asarray(q, dtype=np.float64)
    n = np.linalg.norm(q, axis=-1, keepdims=True)
    big = n > 1e-12
    if big.all():  # the usual case (a crowd's 17,000 rotations a step): the same quotients, without the selects
        return np.true_divide(q, n, order="C")
    return np.where(big, q / np.where(big, n, 1.0), IDENTITY)


def mul(a: ArrayLike, b: ArrayLike) -> F:
    """Hamilton product ``a * b`` (apply ``b`` first, then ``a``)."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    aw, ax, ay, az = a[..., 0], a[..., 1], a[..., 2], a[..., 3]
    bw, bx, by, bz = b[..., 0], b[..., 1], b[..., 2], b[..., 3]
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    out[..., 0] = aw * bw - ax * bx - ay * by - az * bz
    out[..., 1] = aw * bx + ax * bw + ay * bz - az * by
    out[..., 2] = aw * by - ax * bz + ay * bw + az * bx
    out[..., 3] = aw * bz + ax * by - ay * bx + az * bw
    return out


def conjugate(q: ArrayLike) -> F:
    """Conjugate, which is the inverse of a unit quaternion."""
    q = np.array(q, dtype=np.float64)
    q[..., 1:] *= -1.0
    return q


def _cross(a: F, b: F) -> F:
    """``a × b`` over the last axis, written out: ``np.cross`` is slow on small arrays."""
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    out[..., 0] = a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1]
    out[..., 1] = a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2]
    out[..., 2] = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    return out


def rotate(q: ArrayLike, v: ArrayLike) -> F:
    """Rotate vectors ``v [...,3]`` by unit quaternions ``q [...,4]``.

    Uses ``v + 2w(u×v) + 2u×(u×v)``, which is cheaper than two products.
    """
    q = np.asarray(q, dtype=np.float64)
    v = np.asarray(v, dtype=np.float64)
    u = q[..., 1:]
    w = q[..., :1]
    t = 2.0 * _cross(u, v)
    return v + w * t + _cross(u, t)


def from_axis_angle(axis: ArrayLike, angle: ArrayLike) -> F:
    """Rotation of ``angle`` radians about ``axis`` (normalised here)."""
    axis = np.asarray(axis, dtype=np.float64)
    angle = np.asarray(angle, dtype=np.float64)
    n = np.linalg.norm(axis, axis=-1, keepdims=True)
    axis = axis / np.where(n > 1e-12, n, 1.0)
    half = 0.5 * angle[..., None]
    return np.concatenate([np.cos(half), np.sin(half) * axis], axis=-1)


def to_axis_angle(q: ArrayLike) -> tuple[F, F]:
    """Axis ``[...,3]`` and angle ``[...]`` in ``[0, π]`` of unit quaternions."""
    q = align_hemisphere(normalize(q))
    s = np.linalg.norm(q[..., 1:], axis=-1)
    angle = 2.0 * np.arctan2(s, q[..., 0])
    axis = np.where(s[..., None] > 1e-12, q[..., 1:] / np.where(s > 1e-12, s, 1.0)[..., None], [1.0, 0.0, 0.0])
    return axis, angle


def log(q: ArrayLike) -> F:
    """Rotation vector (axis × angle) of unit quaternions, the shortest way round."""
    axis, angle = to_axis_angle(q)
    return axis * angle[..., None]


def exp(r: ArrayLike) -> F:
    """Unit quaternion of a rotation vector (inverse of :func:`log`)."""
    r = np.asarray(r, dtype=np.float64)
    angle = np.linalg.norm(r, axis=-1)
    half = 0.5 * angle
    # sin(x/2)/x with its limit 1/2 at zero, so small rotations stay exact.
    k = np.where(angle > 1e-9, np.sin(half) / np.where(angle > 1e-9, angle, 1.0), 0.5 - angle**2 / 48.0)
    return np.concatenate([np.cos(half)[..., None], r * k[..., None]], axis=-1)


def align_hemisphere(q: ArrayLike, reference: ArrayLike | None = None) -> F:
    """Flip signs so each quaternion lies in the hemisphere of ``reference`` (default: w ≥ 0).

    ``q`` and ``-q`` are the same rotation; blending needs them on one side.
    """
    q = np.asarray(q, dtype=np.float64)
    ref = IDENTITY if reference is None else np.asarray(reference, dtype=np.float64)
    d = np.sum(q * ref, axis=-1, keepdims=True)
    return np.where(d < 0.0, -q, q)


def slerp(a: ArrayLike, b: ArrayLike, t: ArrayLike) -> F:
    """Spherical interpolation from ``a`` to ``b`` along the shorter arc; ``t`` broadcasts."""
    a = np.asarray(a, dtype=np.float64)
    b = align_hemisphere(b, a)
    t = np.asarray(t, dtype=np.float64)[..., None] if np.ndim(t) else np.asarray(t, dtype=np.float64)
    d = np.clip(np.sum(a * b, axis=-1, keepdims=True), -1.0, 1.0)
    theta = np.arccos(d)
    s = np.sin(theta)
    small = s < 1e-6
    safe = np.where(small, 1.0, s)
    wa = np.where(small, 1.0 - t, np.sin((1.0 - t) * theta) / safe)
    wb = np.where(small, t, np.sin(t * theta) / safe)
    return normalize(wa * a + wb * b)


def nlerp(a: ArrayLike, b: ArrayLike, t: ArrayLike) -> F:
    """Normalised linear interpolation: cheaper than slerp, same endpoints and path."""
    a = np.asarray(a, dtype=np.float64)
    b = align_hemisphere(b, a)
    t = np.asarray(t, dtype=np.float64)[..., None] if np.ndim(t) else np.asarray(t, dtype=np.float64)
    return normalize((1.0 - t) * a + t * b)


def to_matrix(q: ArrayLike) -> F:
    """3×3 rotation matrices ``[...,3,3]`` of unit quaternions."""
    q = np.asarray(q, dtype=np.float64)
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    m = np.empty(q.shape[:-1] + (3, 3))
    m[..., 0, 0] = 1 - 2 * (y * y + z * z)
    m[..., 0, 1] = 2 * (x * y - w * z)
    m[..., 0, 2] = 2 * (x * z + w * y)
    m[..., 1, 0] = 2 * (x * y + w * z)
    m[..., 1, 1] = 1 - 2 * (x * x + z * z)
    m[..., 1, 2] = 2 * (y * z - w * x)
    m[..., 2, 0] = 2 * (x * z - w * y)
    m[..., 2, 1] = 2 * (y * z + w * x)
    m[..., 2, 2] = 1 - 2 * (x * x + y * y)
    return m


def from_matrix(m: ArrayLike) -> F:
    """Unit quaternions (w ≥ 0) of rotation matrices, by Shepperd's stable method."""
    m = np.asarray(m, dtype=np.float64)
    tr = m[..., 0, 0] + m[..., 1, 1] + m[..., 2, 2]
    cand = np.stack(
        [
            np.stack(
                [1 + tr, m[..., 2, 1] - m[..., 1, 2], m[..., 0, 2] - m[..., 2, 0], m[..., 1, 0] - m[..., 0, 1]], -1
            ),
            np.stack(
                [
                    m[..., 2, 1] - m[..., 1, 2],
                    1 + 2 * m[..., 0, 0] - tr,
                    m[..., 0, 1] + m[..., 1, 0],
                    m[..., 0, 2] + m[..., 2, 0],
                ],
                -1,
            ),
            np.stack(
                [
                    m[..., 0, 2] - m[..., 2, 0],
                    m[..., 0, 1] + m[..., 1, 0],
                    1 + 2 * m[..., 1, 1] - tr,
                    m[..., 1, 2] + m[..., 2, 1],
                ],
                -1,
            ),
            np.stack(
                [
                    m[..., 1, 0] - m[..., 0, 1],
                    m[..., 0, 2] + m[..., 2, 0],
                    m[..., 1, 2] + m[..., 2, 1],
                    1 + 2 * m[..., 2, 2] - tr,
                ],
                -1,
            ),
        ],
        axis=-2,
    )
    diag = np.stack([tr, m[..., 0, 0], m[..., 1, 1], m[..., 2, 2]], -1)
    best = np.argmax(diag, axis=-1)
    q = np.take_along_axis(cand, best[..., None, None], axis=-2)[..., 0, :]
    return align_hemisphere(normalize(q))


_AXES = {"x": np.array([1.0, 0.0, 0.0]), "y": np.array([0.0, 1.0, 0.0]), "z": np.array([0.0, 0.0, 1.0])}


def from_euler(order: str, angles: ArrayLike, degrees: bool = False) -> F:
    """Quaternions from intrinsic Euler angles, ``order`` like ``"zxy"`` (as BVH channels list them).

    ``angles[..., k]`` is the rotation about ``order[k]``; the composed rotation is
    ``R = R[order[0]] · R[order[1]] · R[order[2]]``, the BVH convention.
    """
    rad = np.asarray(angles, dtype=np.float64)
    if degrees:
        rad = np.radians(rad)
    q = identity(*rad.shape[:-1])
    for k, axis in enumerate(order.lower()):
        q = mul(q, from_axis_angle(_AXES[axis], rad[..., k]))
    return q


def to_euler(order: str, q: ArrayLike, degrees: bool = False) -> F:
    """Intrinsic Euler angles of ``q`` in ``order`` (inverse of :func:`from_euler`), via scipy."""
    from scipy.spatial.transform import Rotation

    q = np.asarray(q, dtype=np.float64)
    flat = to_xyzw(q.reshape(-1, 4))
    ang = Rotation.from_quat(flat).as_euler(order.upper(), degrees=degrees)
    return ang.reshape(q.shape[:-1] + (3,))


def between(u: ArrayLike, v: ArrayLike) -> F:
    """Shortest-arc rotation taking direction ``u`` to direction ``v``."""
    ua = np.asarray(u, dtype=np.float64)
    va = np.asarray(v, dtype=np.float64)
    un = ua / np.linalg.norm(ua, axis=-1, keepdims=True)
    vn = va / np.linalg.norm(va, axis=-1, keepdims=True)
    d = np.sum(un * vn, axis=-1, keepdims=True)
    c = np.cross(un, vn)
    q = np.concatenate([1.0 + d, c], axis=-1)
    # Opposite vectors: any axis perpendicular to u works.
    opposite = (1.0 + d[..., 0]) < 1e-9
    if np.any(opposite):
        perp = np.cross(un, [1.0, 0.0, 0.0])
        weak = np.linalg.norm(perp, axis=-1, keepdims=True) < 1e-6
        perp = np.where(weak, np.cross(un, [0.0, 1.0, 0.0]), perp)
        q = np.where(opposite[..., None], np.concatenate([np.zeros_like(d), perp], axis=-1), q)
    return normalize(q)


def swing_twist(q: ArrayLike, axis: ArrayLike) -> tuple[F, F]:
    """Split ``q = swing * twist`` where ``twist`` turns about ``axis`` (unit) and ``swing`` is perpendicular.

    Used for cone/twist joint limits and for reading a heading out of a root rotation.
    """
    q = np.asarray(q, dtype=np.float64)
    axis = np.asarray(axis, dtype=np.float64)
    proj = np.sum(q[..., 1:] * axis, axis=-1, keepdims=True) * axis
    twist = np.concatenate([q[..., :1], np.broadcast_to(proj, q[..., 1:].shape)], axis=-1)
    n = np.linalg.norm(twist, axis=-1, keepdims=True)
    # A 180° swing leaves no twist information: call the twist the identity.
    twist = np.where(n > 1e-9, twist / np.where(n > 1e-9, n, 1.0), IDENTITY)
    swing = mul(q, conjugate(twist))
    return swing, twist


def angle_between(a: ArrayLike, b: ArrayLike) -> F:
    """Rotation angle in radians (0..π) from ``a`` to ``b``."""
    d = np.abs(np.sum(np.asarray(a) * np.asarray(b), axis=-1))
    return 2.0 * np.arccos(np.clip(d, 0.0, 1.0))


def from_xyzw(q: ArrayLike) -> F:
    """Convert scalar-last (scipy, Unity, ZIG SIM) to our scalar-first order."""
    q = np.asarray(q, dtype=np.float64)
    return np.concatenate([q[..., 3:], q[..., :3]], axis=-1)


def to_xyzw(q: ArrayLike) -> F:
    """Convert our scalar-first quaternions to scalar-last (scipy)."""
    q = np.asarray(q, dtype=np.float64)
    return np.concatenate([q[..., 1:], q[..., :1]], axis=-1)
