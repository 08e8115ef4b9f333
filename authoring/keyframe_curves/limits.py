"""Tangent limits of thesis Eq. 4.7–4.9 and the timing edit of Eq. 4.12.

For a channel ``c_i`` limited to ``[u_i, v_i]`` and the segment ``[t_k, t_{k+1}]``:

- time components (Eq. 4.7): ``0 ≤ θ^X_{k+} ≤ t_{k+1} − t_k`` and ``0 ≤ θ^X_{k+1−} ≤ t_{k+1} − t_k``,
  which keeps the curve a function of time;
- value components (Eq. 4.8–4.9): ``φ ≤ θ^Y_{k+} ≤ ψ`` and ``−ψ ≤ θ^Y_{k+1−} ≤ −φ`` with
  ``φ = 4/3 (u − min(c(t_k), c(t_{k+1})))`` and ``ψ = 4/3 (v − max(c(t_k), c(t_{k+1})))``.
  Appendix A shows the whole segment then stays in ``[u, v]`` (keys inside the limits
  assumed; :func:`segment_bounds` widens a limit to a key that lies outside it, so an edit
  never has to move a key).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from engine.keyframes import BezierCurves

__all__ = ["segment_bounds", "retime_segment"]

from engine.arrays import F64 as F


def segment_bounds(
    curves: BezierCurves, k: int, channels: ArrayLike, lower: ArrayLike, upper: ArrayLike
) -> tuple[F, F]:
    """``(lo, hi)`` ``[4C']`` of ``[θ^X_{k+}, θ^Y_{k+}, θ^X_{k+1−}, θ^Y_{k+1−}]`` per channel block.

    Args:
        curves: the curves; k: the segment; channels: ``[C']`` channel indices;
        lower, upper: ``[C']`` the channels' limits ``u``, ``v``.
    """
    ch = np.asarray(channels, dtype=np.int64)
    gap = float(curves.times[k + 1] - curves.times[k])
    a, b = curves.values[k, ch], curves.values[k + 1, ch]
    u = np.minimum(np.asarray(lower, dtype=np.float64), np.minimum(a, b))
    v = np.maximum(np.asarray(upper, dtype=np.float64), np.maximum(a, b))
    phi = 4.0 / 3.0 * (u - np.minimum(a, b))
    psi = 4.0 / 3.0 * (v - np.maximum(a, b))
    z, g = np.zeros_like(phi), np.full_like(phi, gap)
    return np.concatenate([z, phi, z, -psi]), np.concatenate([g, psi, g, -phi])


def retime_segment(curves: BezierCurves, t: float, sigma: float, channels: ArrayLike | None = None) -> BezierCurves:
    """Eq. 4.12: scale the timing at ``t`` by ``σ`` (seconds of tangent length; > 0 speeds up there).

    ``θ^X_{k+} += σ (t − t_k)/Δt`` and ``θ^X_{k+1−} += σ (t_{k+1} − t)/Δt`` on every channel
    (or ``channels``), kept inside ``[0, Δt]`` so the curves stay functions of time.
    """
    if not np.isfinite(sigma):
        raise ValueError("timing scale must be finite")
    k = int(curves.segment_of(t))
    t0, t1 = float(curves.times[k]), float(curves.times[k + 1])
    gap = t1 - t0
    ch = np.arange(curves.num_channels) if channels is None else np.asarray(channels, dtype=np.int64)
    out_x, in_x = np.array(curves.out_x), np.array(curves.in_x)
    out_x[k, ch] = np.clip(out_x[k, ch] + sigma * (t - t0) / gap, 0.0, gap)
    in_x[k + 1, ch] = np.clip(in_x[k + 1, ch] + sigma * (t1 - t) / gap, 0.0, gap)
    return curves.with_tangents(out_x, np.array(curves.out_y), in_x, np.array(curves.in_y))
