"""Average cycle (paper §4, "Average cycle"): cut, put in correspondence, time-align, average.

The performance is cut at the cleaned matches of the anchor point into cycles
``c_1 … c_p``. A few evenly spaced points of a reference cycle are matched into every
other cycle with the same descriptor ``d_D`` (each within ``±T/8`` of its proportional
place, refined to sub-sample time by a parabola through the dip). Every cycle is then
rescaled in time, piecewise linearly between those correspondences, so that matching
points share one phase, and the aligned cycles are averaged.

Quaternion items are averaged on the sphere: every cycle's sample is put in the
hemisphere of the reference cycle's sample at the same phase, the 4-vectors are
summed and renormalised (the chordal mean, exact to second order for the small
spreads of a performance). Positions of a *travelling* item (a root walking forward)
are averaged relative to each cycle's start, so three strides at three places on
the floor give one stride, not a smear.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from authoring.cycles.descriptor import Descriptor
from authoring.cycles.trajectory import Trajectory
from engine import quat

__all__ = ["AlignedCycles", "align_cycles", "average_cycles", "sample_linear"]


@dataclass(frozen=True)
class AlignedCycles:
    """The cycles resampled on one common phase grid.

    Attributes:
        cuts: ``[p, 2]`` first and last sample index of each cycle (consecutive repetitions
            of the anchor; where a repetition was missed no cycle spans the gap).
        knots_phase: ``[M+2]`` common phases of the correspondences (0 and 1 at the ends).
        knots_time: ``[p, M+2]`` the time of each correspondence in each cycle.
        phases: ``[S+1]`` phase grid, 0..1 inclusive.
        values: ``[p, S+1, N]`` each cycle sampled on the grid (travel columns start at 0).
        starts: ``[p, N]`` each cycle's value at its start (used for travel columns).
    """

    cuts: NDArray[np.int64]
    knots_phase: NDArray[np.float64]
    knots_time: NDArray[np.float64]
    phases: NDArray[np.float64]
    values: NDArray[np.float64]
    starts: NDArray[np.float64]

    @property
    def count(self) -> int:
        """Number of cycles ``p``."""
        return int(self.values.shape[0])


def sample_linear(
    times: NDArray[np.float64], values: NDArray[np.float64], at: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Values at times ``at`` by linear interpolation of the rows (all columns at once)."""
    at = np.clip(at, times[0], times[-1])
    i = np.clip(np.searchsorted(times, at, side="right") - 1, 0, len(times) - 2)
    w = ((at - times[i]) / (times[i + 1] - times[i]))[..., None]
    return values[i] * (1.0 - w) + values[i + 1] * w


def _dip_time(times: NDArray[np.float64], row: NDArray[np.float64], j: int) -> float:
    """Sub-sample time of a minimum at ``j`` from the parabola through its neighbours."""
    if j <= 0 or j >= len(row) - 1:
        return float(times[j])
    a, b, c = row[j - 1], row[j], row[j + 1]
    den = a - 2.0 * b + c
    if den <= 1e-300:
        return float(times[j])
    x = float(np.clip(0.5 * (a - c) / den, -0.5, 0.5))
    return float(times[j] + x * (times[j + 1] - times[j]) if x >= 0 else times[j] + x * (times[j] - times[j - 1]))


def align_cycles(
    traj: Trajectory, descriptor: Descriptor, cuts: NDArray[np.int64], samples: int, tolerance: float = 1.0 / 8.0
) -> AlignedCycles:
    """Correspondences by ``d_D`` between the cycles ``cuts [p, 2]``, then a common time base."""
    t = traj.times
    cuts = np.asarray(cuts, dtype=np.int64).reshape(-1, 2)
    starts_t, ends_t = t[cuts[:, 0]], t[cuts[:, 1]]
    dur = ends_t - starts_t
    p = len(dur)
    ref = int(np.argmin(np.abs(dur - np.median(dur))))
    ref_len = int(cuts[ref, 1] - cuts[ref, 0])
    m = int(np.clip(ref_len // 6, 1, 12))
    frac = np.arange(1, m + 1) / (m + 1)
    probes = cuts[ref, 0] + np.round(frac * ref_len).astype(np.int64)
    probes = np.unique(np.clip(probes, cuts[ref, 0] + 1, cuts[ref, 1] - 1))
    frac = (t[probes] - starts_t[ref]) / dur[ref]
    m = len(probes)
    rows = descriptor.rows(probes) if m else np.zeros((0, len(t)))
    ktime = np.empty((p, m + 2))
    ktime[:, 0], ktime[:, -1] = starts_t, ends_t
    for c in range(p):
        lo_i, hi_i = int(cuts[c, 0]) + 1, int(cuts[c, 1]) - 1
        for k in range(m):
            expect = starts_t[c] + frac[k] * dur[c]
            if c == ref:
                ktime[c, k + 1] = t[probes[k]]
                continue
            win = np.flatnonzero((t >= expect - tolerance * dur[c]) & (t <= expect + tolerance * dur[c]))
            win = win[(win >= lo_i) & (win <= hi_i)]
            if len(win) == 0:
                ktime[c, k + 1] = expect
                continue
            j = int(win[np.argmin(rows[k, win])])
            ktime[c, k + 1] = _dip_time(t, rows[k], j)
        # Correspondences must keep their order; one that does not falls back to its proportional place.
        for k in range(1, m + 1):
            if not ktime[c, k - 1] < ktime[c, k] < ends_t[c]:
                ktime[c, k] = starts_t[c] + frac[k - 1] * dur[c]
        if np.any(np.diff(ktime[c]) <= 0):
            ktime[c, 1:-1] = starts_t[c] + frac * dur[c]
    kphase = np.mean((ktime - starts_t[:, None]) / dur[:, None], axis=0)
    phases = np.linspace(0.0, 1.0, samples + 1)
    vals = np.empty((p, samples + 1, traj.dims))
    for c in range(p):
        at = np.interp(phases, kphase, ktime[c])
        vals[c] = sample_linear(t, traj.values, at)
    starts = vals[:, 0, :].copy()
    for it in traj.items:
        if it.kind == "position" and it.travel:
            vals[:, :, it.columns] -= starts[:, None, it.columns]
    return AlignedCycles(cuts, kphase, ktime, phases, vals, starts)


def average_cycles(traj: Trajectory, aligned: AlignedCycles) -> NDArray[np.float64]:
    """The mean cycle ``[S+1, N]``: arithmetic for vectors, hemisphere-aligned chordal mean for quaternions."""
    vals = aligned.values
    mean = vals.mean(axis=0)
    for it in traj.items:
        if it.kind == "position" and it.travel:
            mean[:, it.columns] += aligned.starts[:, it.columns].mean(axis=0)
        if it.kind == "rotation":
            q = vals[:, :, it.columns]
            ref = q[int(np.argmin(np.abs(np.arange(len(q)) - len(q) // 2)))]
            q = quat.align_hemisphere(q, ref[None])
            mean[:, it.columns] = quat.normalize(q.sum(axis=0))
    return mean
