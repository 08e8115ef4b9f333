"""``puppetphone bench cycles``: cycle extraction time by dimension and length, and period accuracy.

Figures:

* ``cycle_s_254d`` — seconds to extract a 254-dimension, 1,000-frame walk-like performance
  (goal < 0.1 s; the paper's mocap walk had 254 dimensions);
* ``cycle_s_7804d`` — seconds for 7,804 dimensions (the paper's cloth), 600 frames (goal < 1 s);
* ``cycle_s_<N>d_<F>f`` — the rest of the grid, to see how time grows with N and length;
* ``cycle_s_mocap_walk_175d`` — the real CMU 16_15 walk from ``../shared/data`` (when present);
* ``period_error_pct_descriptor`` — median period error over jittered performances (±15 %
  per cycle, noise, drift, N = 1…254), against the FFT/autocorrelation estimator on the
  very same inputs as its baseline ``period_error_pct_fft``;
* ``period_error_pct_*_worst`` — the worst case of each, where frequency methods fail;
* ``*_all_jittered`` — the same with the first and last cycles jittered too (by default
  they run at the nominal tempo, so the mean over the whole cycles between matches is
  the true period; here it is not, which bounds what any estimator can reach).
"""

from __future__ import annotations

import numpy as np

from authoring.cycles.baseline import autocorrelation_period
from authoring.cycles.extract import extract_cycle
from authoring.cycles.synthetic import make_performance
from puppetphone.bench.figures import Figure, median_time

__all__ = ["run"]

BENCH = "cycles"


def _time(dims: int, frames: int, repeats: int) -> float:
    # A period of about 1 s and as many cycles as fit: 120 fps for 1,000 frames is a mocap walk.
    fps = 120.0 if frames >= 900 else 60.0
    cycles = max(3, round(frames / fps))
    perf = make_performance(
        dims, np.random.default_rng(dims + frames), cycles=cycles, period=frames / fps / cycles, fps=fps
    )
    traj = perf.trajectory
    return median_time(lambda: extract_cycle(traj, np.random.default_rng(0)), repeats=repeats, min_time=0.0)


def _accuracy(seeds: int = 12, steady_ends: bool = True) -> tuple[list[float], list[float]]:
    desc, fft = [], []
    for dims in (1, 2, 60, 254):
        for s in range(seeds):
            perf = make_performance(
                dims,
                np.random.default_rng(1000 * dims + s),
                cycles=8,
                jitter=0.15,
                noise=0.02,
                drift=0.1,
                steady_ends=steady_ends,
            )
            r = extract_cycle(perf.trajectory, np.random.default_rng(s))
            desc.append(100.0 * abs(r.period / perf.period - 1.0))
            f = autocorrelation_period(perf.trajectory)
            fft.append(100.0 * abs(f / perf.period - 1.0) if np.isfinite(f) else 100.0)
    return desc, fft


def _mocap_walk() -> float | None:
    """Seconds on the real CMU 16_15 walk (175 dims: root + 43 joint quaternions, 467 frames), if the data is here."""
    import os
    from pathlib import Path

    from authoring.cycles.formats import load_performance

    root = Path(os.environ.get("PUPPETPHONE_DATA", Path(__file__).resolve().parents[3] / "shared" / "data"))
    path = root / "mocap" / "cmu_16_15_walk_daz.bvh"
    if not path.is_file():
        return None
    traj = load_performance(path).trajectory
    return median_time(lambda: extract_cycle(traj, np.random.default_rng(0)), repeats=7, min_time=0.0)


def run() -> list[Figure]:
    """Measure and return the figures."""
    figs = [
        Figure(BENCH, "cycle_s_254d", _time(254, 1000, 7), "s", "goal", 0.1),
        Figure(BENCH, "cycle_s_7804d", _time(7804, 600, 3), "s", "goal (paper: under one second)", 1.0),
    ]
    for dims, frames in ((2, 1000), (60, 1000), (254, 4000), (2611, 600)):
        figs.append(Figure(BENCH, f"cycle_s_{dims}d_{frames}f", _time(dims, frames, 3), "s"))
    walk = _mocap_walk()
    if walk is not None:
        figs.append(Figure(BENCH, "cycle_s_mocap_walk_175d", walk, "s", "goal", 0.1))
    desc, fft = _accuracy()
    figs.append(
        Figure(
            BENCH,
            "period_error_pct_descriptor",
            float(np.median(desc)),
            "%",
            "period_error_pct_fft",
            float(np.median(fft)),
        )
    )
    figs.append(
        Figure(
            BENCH,
            "period_error_pct_descriptor_worst",
            float(np.max(desc)),
            "%",
            "period_error_pct_fft_worst",
            float(np.max(fft)),
        )
    )
    figs.append(Figure(BENCH, "period_error_pct_fft", float(np.median(fft)), "%"))
    # Every cycle jittered, ends included: the true mean is partly outside what any method sees.
    desc, fft = _accuracy(steady_ends=False)
    figs.append(
        Figure(
            BENCH,
            "period_error_pct_descriptor_all_jittered",
            float(np.median(desc)),
            "%",
            "period_error_pct_fft_all_jittered",
            float(np.median(fft)),
        )
    )
    figs.append(
        Figure(
            BENCH,
            "period_error_pct_descriptor_all_jittered_worst",
            float(np.max(desc)),
            "%",
            "period_error_pct_fft_all_jittered_worst",
            float(np.max(fft)),
        )
    )
    return figs
