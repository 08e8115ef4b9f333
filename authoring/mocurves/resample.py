"""Resampling a cycle at warped times (paper §5.2's last step, Fig. 4).

After the time-warp QP, frame ``i`` must show what the original showed at ``t*_i``. Each
channel is read off the original at those times with the interpolant that suits it:
positions and scales with a *periodic* cubic spline (C², closed across the seam, so a warp
never adds a kink at the loop point), rotations with slerp between the bracketing keys
(the clip's own convention, exact at the keys). Root motion, which accumulates over
cycles, is resampled as travel so a warped walk still covers the same ground per cycle.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.interpolate import CubicSpline

from engine import quat
from engine.clip import Clip, RootMotion

__all__ = ["periodic_cubic", "periodic_slerp", "retime_clip"]

from engine.arrays import F64 as F


def periodic_cubic(values: ArrayLike, period: float, times: ArrayLike) -> F:
    """Values ``[N,...]`` sampled uniformly over one period, read at ``times`` (wrapped) by a periodic cubic spline."""
    v = np.asarray(values, dtype=np.float64)
    n = len(v)
    t = np.mod(np.asarray(times, dtype=np.float64), period)
    if n < 3:
        return np.broadcast_to(v[0], t.shape + v.shape[1:]).copy()
    knots = np.arange(n + 1) * (period / n)
    spline = CubicSpline(knots, np.concatenate([v, v[:1]]), axis=0, bc_type="periodic")
    return np.asarray(spline(t), dtype=np.float64)


def periodic_slerp(rotations: ArrayLike, period: float, times: ArrayLike) -> F:
    """Quaternions ``[N,...,4]`` sampled uniformly over one period, slerped at ``times`` (wrapped)."""
    q = np.asarray(rotations, dtype=np.float64)
    n = len(q)
    f = np.mod(np.asarray(times, dtype=np.float64), period) * (n / period)
    i0 = np.floor(f).astype(np.int64) % n
    i1 = (i0 + 1) % n
    a = (f - np.floor(f)).reshape((-1,) + (1,) * (q.ndim - 2))  # slerp appends the last axis itself
    b = quat.align_hemisphere(q[i1], q[i0])
    return quat.slerp(q[i0], b, a)


def retime_clip(clip: Clip, times: ArrayLike, joints: Sequence[int] | None = None,
                scales: ArrayLike | None = None) -> tuple[Clip, F | None]:  # fmt: skip
    """The looping ``clip`` with frame ``i`` showing its motion at ``times[i]`` (seconds).

    Args:
        clip: a looping clip of ``F`` frames.
        times: ``[F]`` (or ``[F+1]``, the seam entry ignored) source times per frame.
        joints: the layer to warp; ``None`` warps every joint. The root position and root
            motion follow joint 0 (the root) being in the layer.
        scales: optional ``[F,J]`` per-joint scale tracks, warped with the same layer.

    Returns:
        The retimed clip and the retimed scales (``None`` when none were given).
    """
    if not clip.loop:
        raise ValueError(f"clip {clip.name!r} is not a loop: MoCurves time warps are periodic")
    n = clip.num_frames
    t = np.asarray(times, dtype=np.float64)[:n]
    if t.shape != (n,) or not np.all(np.isfinite(t)):
        raise ValueError(f"times must be {n} finite seconds, got shape {t.shape}")
    layer = np.arange(clip.skeleton.num_joints) if joints is None else np.unique(np.asarray(joints, dtype=np.int64))
    period = clip.duration
    rot = clip.rotations.copy()
    rot[:, layer] = periodic_slerp(clip.rotations[:, layer], period, t)
    rot = _unit_fixed_point(rot)
    root, rm = clip.root, clip.root_motion
    if 0 in layer:
        root = periodic_cubic(clip.root, period, t)
        if rm is not None:
            samples = [clip.sample_root_motion(float(x)) for x in t]
            rm = RootMotion(np.array([s[0] for s in samples]), np.array([s[1] for s in samples]))
    new_scales = None
    if scales is not None:
        s = np.asarray(scales, dtype=np.float64)
        new_scales = s.copy()
        new_scales[:, layer] = periodic_cubic(s[:, layer], period, t)
    return replace(clip, root=root, rotations=rot, root_motion=rm), new_scales


def _unit_fixed_point(q: NDArray[np.float64]) -> NDArray[np.float64]:
    """Quaternions that normalising leaves bit-for-bit unchanged.

    ``Clip`` normalises its rotations on construction, and dividing by the norm is not
    always idempotent in the last bit — some values flip between two neighbours forever.
    A saved clip must load back byte-identical (its digest pairs it with its MoCurves side
    file), so the rows that still change are nudged by one ulp (far below any visible or
    simulated effect) until normalisation leaves them alone. Checked on the whole
    ``[F,J,4]`` array as ``Clip`` sees it: the norm's summation order depends on the layout.
    """
    q = quat.normalize(q)
    for _ in range(32):
        nq = quat.normalize(q)
        bad = (nq != q).any(axis=-1)
        if not bad.any():
            return q
        q = nq
        q[bad, 0] = np.nextafter(q[bad, 0], np.inf)
    return q
