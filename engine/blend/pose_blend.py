"""Weighted pose blending over numpy arrays: the one ``blend(weights, poses)`` contract.

Every blendable in the engine (blend spaces, cross-fades, additive layers) reduces to
a weighted combination of ``K`` poses. The clip axis sits just before the joint
axis — rotations ``[..., K, J, 4]``, roots ``[..., K, 3]``, weights ``[..., K]`` — so
one call blends every joint of every puppet in a batch.

Rotations: quaternions ``q`` and ``-q`` are the same rotation, so before summing,
each is flipped into the hemisphere of the most heavily weighted input (per joint);
the normalised weighted sum (``"nlerp"``) is then the chordal L2 mean, exact for two
inputs along the slerp path up to the usual nlerp speed distortion and cheap. For
widely spread inputs the ``"mean"`` method refines it to the Karcher (geodesic) mean
by a few Gauss–Newton steps in the tangent space (Buss & Fillmore 2001), which is
independent of the order of the inputs and of how far apart they are.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike

from engine import quat
from engine.pose import Pose

__all__ = [
    "blend_quaternions",
    "blend_vectors",
    "blend",
    "additive_delta",
    "apply_additive",
    "crossfade",
    "fade_weight",
]

from engine.arrays import F64 as F


def _check_weights(weights: ArrayLike, k: int) -> F:
    w = np.asarray(weights, dtype=np.float64)
    if w.shape[-1:] != (k,):
        raise ValueError(f"weights must end in an axis of {k} (one per pose), got shape {w.shape}")
    if not np.isfinite(w).all():
        raise ValueError("weights contain NaN or infinite values")
    total = w.sum(axis=-1, keepdims=True)
    if np.any(np.abs(total) < 1e-12):
        raise ValueError("weights sum to zero: nothing to blend")
    return w / total


def blend_quaternions(weights: ArrayLike, quats: ArrayLike, method: str = "nlerp", iterations: int = 4) -> F:
    """Weighted average of unit quaternions along axis ``-2`` of ``quats [..., K, 4]``.

    Args:
        weights: ``[..., K]`` (broadcast against the batch axes; normalised to sum to one).
        quats: ``[..., K, 4]`` unit quaternions.
        method: ``"nlerp"`` (normalised weighted sum) or ``"mean"`` (Karcher mean).
        iterations: Gauss–Newton steps of ``"mean"``.
    """
    q = np.asarray(quats, dtype=np.float64)
    w = _check_weights(weights, q.shape[-2])
    # Reference per batch element: the input with the largest weight.
    ref_idx = np.argmax(np.broadcast_to(w, q.shape[:-1]), axis=-1)
    ref = np.take_along_axis(q, ref_idx[..., None, None], axis=-2)
    q = quat.align_hemisphere(q, ref)
    mean = quat.normalize(np.sum(w[..., None] * q, axis=-2))
    if method == "nlerp":
        return mean
    if method != "mean":
        raise ValueError(f"unknown blend method {method!r}; use 'nlerp' or 'mean'")
    for _ in range(iterations):
        rel = quat.mul(quat.conjugate(mean)[..., None, :], q)
        step = np.sum(w[..., None] * quat.log(rel), axis=-2)
        mean = quat.normalize(quat.mul(mean, quat.exp(step)))
    return mean


def blend_vectors(weights: ArrayLike, vectors: ArrayLike) -> F:
    """Weighted average of vectors along axis ``-2`` of ``vectors [..., K, D]`` (roots, root motion)."""
    v = np.asarray(vectors, dtype=np.float64)
    w = _check_weights(weights, v.shape[-2])
    return np.sum(w[..., None] * v, axis=-2)


def _channels(poses: Sequence[Pose]) -> tuple[F | None, F | None]:
    """Stacked ``[..., K, J, 3]`` offsets and ``[..., K, J]`` scales of poses that carry them.

    A missing scale is 1; a missing offset is the skeleton's, which a pose does not know,
    so mixing poses with and without offsets is refused (blend spaces fill them from clips).
    """
    have = [p.offsets is not None for p in poses]
    offsets = None
    if any(have):
        if not all(have):
            raise ValueError("some poses carry joint offsets (a translation channel) and some do not")
        offsets = np.stack([np.asarray(p.offsets, dtype=np.float64) for p in poses], axis=-3)
    scales = None
    if any(p.scales is not None for p in poses):
        ones = np.ones(np.shape(poses[0].rotations)[:-1])
        scales = np.stack(
            [ones if p.scales is None else np.asarray(p.scales, dtype=np.float64) for p in poses], axis=-2
        )
    return offsets, scales


def blend(weights: ArrayLike, poses: Sequence[Pose] | Pose, method: str = "nlerp") -> Pose:
    """Blend poses: a list of ``K`` poses, or one stacked ``Pose`` with the clip axis before the joints.

    Returns a new pose with the batch shape of the inputs (the clip axis removed). Joint
    offsets and scales, when the poses carry them, blend linearly with the same weights.
    """
    offsets = scales = None
    if isinstance(poses, Pose):
        root, rot = np.asarray(poses.root), np.asarray(poses.rotations)
        offsets, scales = poses.offsets, poses.scales
    else:
        if len(poses) == 0:
            raise ValueError("no poses to blend")
        joints = {p.num_joints for p in poses}
        if len(joints) != 1:
            raise ValueError(f"poses have different joint counts {sorted(joints)}")
        root = np.stack([np.asarray(p.root, dtype=np.float64) for p in poses], axis=-2)
        rot = np.stack([np.asarray(p.rotations, dtype=np.float64) for p in poses], axis=-3)
        offsets, scales = _channels(poses)
    w = np.asarray(weights, dtype=np.float64)
    # Rotations carry a joint axis after the clip axis: move it before so the clip axis is -2.
    rot_t = np.moveaxis(rot, -3, -2)
    blended = blend_quaternions(w[..., None, :], rot_t, method)
    out = Pose(blend_vectors(w, root), blended)
    if offsets is not None:
        out.offsets = np.sum(_check_weights(w, w.shape[-1])[..., None, None] * np.asarray(offsets), axis=-3)
    if scales is not None:
        out.scales = np.sum(_check_weights(w, w.shape[-1])[..., None] * np.asarray(scales), axis=-2)
    return out


def additive_delta(pose: Pose, reference: Pose) -> Pose:
    """The difference that turns ``reference`` into ``pose``: ``delta = ref⁻¹ · pose`` per joint.

    Stored as an additive layer (a breathing or leaning clip authored on top of the
    rest pose); the root delta is a plain translation difference.
    """
    rot = quat.mul(quat.conjugate(reference.rotations), pose.rotations)
    return Pose(np.asarray(pose.root) - np.asarray(reference.root), quat.align_hemisphere(rot))


def apply_additive(base: Pose, delta: Pose, weight: float | ArrayLike = 1.0) -> Pose:
    """Layer ``weight`` of an additive ``delta`` on ``base``: ``base · slerp(1, delta, weight)``.

    ``weight`` may be a scalar or ``[..., J]`` (a per-joint mask, e.g. upper body only).
    """
    w = np.asarray(weight, dtype=np.float64)
    ident = quat.identity(*np.shape(delta.rotations)[:-1])
    part = quat.slerp(ident, delta.rotations, np.broadcast_to(w, np.shape(delta.rotations)[:-1]))
    root_w = w if w.ndim == 0 else 1.0
    return Pose(np.asarray(base.root) + root_w * np.asarray(delta.root), quat.mul(base.rotations, part))


def crossfade(a: Pose, b: Pose, t: float | ArrayLike) -> Pose:
    """``t`` of the way from pose ``a`` to pose ``b`` (slerp per joint, lerp of the root, offsets and scales)."""
    t = np.asarray(t, dtype=np.float64)
    root = np.asarray(a.root) + t[..., None] * (np.asarray(b.root) - np.asarray(a.root))
    out = Pose(root, quat.slerp(a.rotations, b.rotations, t[..., None] if t.ndim else t))
    if a.offsets is not None or b.offsets is not None or a.scales is not None or b.scales is not None:
        offsets, scales = _channels([a, b])
        if offsets is not None:
            out.offsets = offsets[..., 0, :, :] + t[..., None, None] * (offsets[..., 1, :, :] - offsets[..., 0, :, :])
        if scales is not None:
            out.scales = scales[..., 0, :] + t[..., None] * (scales[..., 1, :] - scales[..., 0, :])
    return out


def fade_weight(elapsed: float, duration: float) -> float:
    """Ease-in-out (smoothstep) weight of a cross-fade ``elapsed`` seconds into ``duration``.

    Smoothstep rather than linear so joint velocities do not jump at the fade ends.
    """
    if duration <= 0.0:
        return 1.0
    x = min(max(elapsed / duration, 0.0), 1.0)
    return x * x * (3.0 - 2.0 * x)
