"""Keyframe tracks: the intent of a motion as a few (time, value) keys, interpolated smoothly.

Cycles use a periodic cubic spline over normalised phase, so the curve and its first two
derivatives join across the loop seam (a loop that closes in value but not in slope shows a
hitch every cycle). One-shot clips (get-up, mid-jump) use PCHIP, which never overshoots its
keys: a hip height keyed at 0.12 m then 0.35 m must not dip below the floor in between.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.interpolate import CubicSpline, PchipInterpolator

__all__ = ["Keys", "periodic", "one_shot", "smoothstep"]

Keys = Sequence[tuple[float, float | Sequence[float] | NDArray[np.float64]]]


def _split(keys: Keys) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    if len(keys) == 0:
        raise ValueError("a track needs at least one key")
    x = np.array([float(k[0]) for k in keys])
    y = np.array([np.atleast_1d(np.asarray(k[1], dtype=np.float64)) for k in keys])
    if len({v.shape for v in y}) != 1:
        raise ValueError("all keys of a track must have the same number of values")
    return x, y


def periodic(keys: Keys, phase: ArrayLike) -> NDArray[np.float64]:
    """Evaluate a looping track at normalised ``phase`` (wrapped to [0, 1)).

    Args:
        keys: ``(phase, value)`` pairs with phases in [0, 1), any order; values may be vectors.
        phase: where to evaluate.

    Returns:
        ``[..., D]`` values (``D`` = number of values per key).
    """
    x, y = _split(keys)
    order = np.argsort(x)
    x, y = np.mod(x[order], 1.0), y[order]
    if np.any(np.diff(x) <= 0):
        raise ValueError(f"periodic keys need distinct phases in [0, 1), got {sorted(x.tolist())}")
    p = np.mod(np.asarray(phase, dtype=np.float64) - x[0], 1.0) + x[0]
    if len(x) == 1:
        return np.broadcast_to(y[0], p.shape + y.shape[1:]).copy()
    xs = np.append(x, x[0] + 1.0)
    ys = np.vstack([y, y[:1]])
    return CubicSpline(xs, ys, bc_type="periodic", axis=0)(p)


def one_shot(keys: Keys, t: ArrayLike) -> NDArray[np.float64]:
    """Evaluate a non-looping track at times ``t``; held flat before the first and after the last key."""
    x, y = _split(keys)
    if np.any(np.diff(x) <= 0):
        raise ValueError("one-shot keys must have strictly increasing times")
    tt = np.clip(np.asarray(t, dtype=np.float64), x[0], x[-1])
    if len(x) == 1:
        return np.broadcast_to(y[0], tt.shape + y.shape[1:]).copy()
    return PchipInterpolator(x, y, axis=0)(tt)


def smoothstep(s: ArrayLike) -> NDArray[np.float64]:
    """``3s² − 2s³`` on [0, 1] (clamped): an ease with zero slope at both ends."""
    s = np.clip(np.asarray(s, dtype=np.float64), 0.0, 1.0)
    return s * s * (3.0 - 2.0 * s)
