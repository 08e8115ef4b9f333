"""The whole pose's autocorrelation: a second opinion on the period when the probes' vote is misled.

The probe points (:mod:`authoring.cycles.period`) each take the *smallest* period whose
repetitions all match. In a short take of a real walk (a CMU walk of 278 frames at 120 fps,
2.3 strides) a third of the stride can pass that test at most points, and the vote settles
on 0.40 s; its "cycles" then alternate between different parts of the stride and are
refused as too different, and the true period no longer has three cycles to win as a
multiple. The whole pose, though, says it plainly: its normalised autocorrelation peaks at
1.00 at 121 frames. :func:`pose_period` finds that peak (travel taken out: only the shape
of the motion counts), and the extractor tries it before refusing, or when the vote's
cycles align poorly (a loop at a sub-period alternates between parts of the stride). It
is a second opinion only: a performer's tempo drifts, which lowers the autocorrelation at
the true period, so a clean vote is never overruled by it.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy.signal import find_peaks

from authoring.cycles.trajectory import Trajectory

__all__ = ["STRONG", "pose_autocorrelation", "pose_period"]

STRONG = 0.8
"""Autocorrelation from which a peak counts as the motion repeating."""
_FUNDAMENTAL = 0.95  # a shorter peak this close to the best is the period (the best may be a multiple)


def pose_autocorrelation(traj: Trajectory, values: NDArray[np.float64], max_lag: int) -> NDArray[np.float64]:
    """``[max_lag+1]`` normalised autocorrelation of the weighted pose (mean and travel ramps removed).

    ``values`` are the trajectory's weighted values; a travelling column's straight ramp is
    taken out (a walk's root moves on every cycle, which says nothing of its shape).
    """
    x = np.array(values, dtype=np.float64)
    t = traj.times - traj.times[0]
    for it in traj.items:
        if it.travel:
            cols = x[:, it.columns]
            slope = np.polyfit(t, cols, 1) if len(t) > 1 else np.zeros((2, cols.shape[1]))
            x[:, it.columns] = cols - np.outer(t, slope[0])
    x -= x.mean(axis=0)
    n = len(x)
    lags = np.arange(min(max_lag, n - 1) + 1)
    spectrum = np.fft.rfft(x, 2 * n, axis=0)
    products = np.fft.irfft(np.sum(np.abs(spectrum) ** 2, axis=1), 2 * n)[lags]  # Σ_t <x_t, x_t+lag>
    energy = np.concatenate([[0.0], np.cumsum(np.sum(x * x, axis=1))])
    den = np.sqrt((energy[n - lags] - energy[0]) * (energy[n] - energy[lags]))
    out = np.zeros(max_lag + 1)
    out[lags] = np.divide(products, den, out=np.zeros(len(lags)), where=den > 0)
    return out


def pose_period(traj: Trajectory, values: NDArray[np.float64], min_lag: int, max_lag: int) -> tuple[int, float] | None:
    """The lag (samples) of the whole pose's strongest autocorrelation peak in ``[min_lag, max_lag]``, and its value.

    The shortest peak within 5 % of the strongest is taken (two periods correlate as well
    as one). ``None`` when no peak reaches :data:`STRONG`.
    """
    if max_lag <= min_lag:
        return None
    r = pose_autocorrelation(traj, values, max_lag)
    peaks, _ = find_peaks(np.concatenate([r, [-np.inf]]))
    peaks = peaks[(peaks >= min_lag) & (peaks <= max_lag)]
    if not len(peaks) or r[peaks].max() < STRONG:
        return None
    top = float(r[peaks].max())
    lag = int(peaks[np.flatnonzero(r[peaks] >= _FUNDAMENTAL * top)[0]])
    return lag, float(r[lag])
