"""The frequency-domain baseline: a period from the FFT autocorrelation of the whole curve.

The paper (§2) tried frequency analysis and dropped it because performed cycles do
not all last equally long. This estimator is the fair version of that idea, so the
benchmark can show the difference on the same inputs: resample to an even grid,
remove each column's mean and linear trend, take every column's autocorrelation by
FFT (zero-padded, so it is linear, not circular), normalise by the overlap, sum over
columns, and return the lag of the highest peak after the first zero crossing,
refined by a parabola. It is also what our data README used to estimate periods.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from authoring.cycles.average import sample_linear
from authoring.cycles.trajectory import Trajectory

__all__ = ["autocorrelation", "autocorrelation_period"]


def autocorrelation(values: NDArray[np.float64]) -> NDArray[np.float64]:
    """Summed, overlap-normalised autocorrelation ``[T]`` of detrended columns ``[T, N]`` (lag 0 = 1)."""
    n = len(values)
    x = np.arange(n) - (n - 1) / 2.0
    v = values - values.mean(axis=0)
    slope = (x @ v) / (x @ x)
    v = v - np.outer(x, slope)
    size = 1 << int(np.ceil(np.log2(2 * n)))
    spec = np.fft.rfft(v, size, axis=0)
    ac = np.fft.irfft(np.sum(np.abs(spec) ** 2, axis=1), size)[:n]
    ac = ac / (n - np.arange(n))
    return ac / ac[0] if ac[0] > 0 else ac


def autocorrelation_period(traj: Trajectory, max_fraction: float = 0.6) -> float:
    """Period in seconds, or ``nan`` when the autocorrelation has no peak."""
    dt = traj.dt
    t = np.arange(traj.times[0], traj.times[-1] + 1e-12, dt)
    v = sample_linear(traj.times, traj.values * traj.weights(), t)
    ac = autocorrelation(v)
    limit = max(3, int(max_fraction * len(ac)))
    neg = np.flatnonzero(ac[:limit] < 0)
    if len(neg) == 0:
        return float("nan")
    start = int(neg[0])
    if limit - start < 3:
        return float("nan")
    k = start + int(np.argmax(ac[start:limit]))
    if k <= start or k >= limit - 1 or ac[k] <= 0:
        return float("nan")
    a, b, c = ac[k - 1], ac[k], ac[k + 1]
    den = a - 2 * b + c
    shift = 0.5 * (a - c) / den if den < 0 else 0.0
    return float((k + shift) * dt)
