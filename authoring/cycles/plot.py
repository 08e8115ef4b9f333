"""The ``--plot`` figure: what the paper's Fig. 2 and Fig. 9 show, for any performance.

Top: the performance over time with the cut points (paper Fig. 2a). Bottom left: the
cycles after time alignment, one thin line each (Fig. 2c), and the extracted loop in
green (Fig. 9's colour for the result). Bottom right: each cycle's correspondence
times against phase, which shows how much the non-uniform rescaling had to bend.

High-dimensional performances are shown through their strongest columns (largest
weighted variance), so a 7,804-dimension cloth still gives a readable picture.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from authoring.cycles.extract import CycleResult
from authoring.cycles.trajectory import Trajectory
from engine.atomic import atomic_write_bytes

__all__ = ["plot_cycle"]

GREEN = "#1a9e3a"


def plot_cycle(
    traj: Trajectory, result: CycleResult, path: str | Path, names: tuple[str, ...] = (), columns: int = 3
) -> Path:
    """Draw the performance, cuts, aligned cycles and loop into a PNG at ``path``."""
    import matplotlib

    matplotlib.use("Agg")
    import io

    import matplotlib.pyplot as plt

    w = traj.weights()
    strength = np.var(traj.values * w, axis=0)
    cols = np.argsort(strength)[::-1][: max(1, columns)]
    fig = plt.figure(figsize=(11, 7), dpi=90)
    top = fig.add_subplot(2, 1, 1)
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for n, c in enumerate(cols):
        label = names[c] if c < len(names) else f"column {c}"
        top.plot(traj.times, traj.values[:, c], lw=1.0, color=colors[n % len(colors)], label=label)
    for cut in np.unique(result.aligned.cuts):
        top.axvline(traj.times[cut], color="crimson", lw=0.8, ls="--")
    top.set_title(
        f"performance: {result.cycles} cycles, period {result.period:.3f} s ({result.period_samples:.1f} samples)"
    )
    top.set_xlabel("time (s)")
    top.legend(loc="upper right", fontsize=8)
    left = fig.add_subplot(2, 2, 3)
    phases = result.aligned.phases
    closed = result.closed()
    for n, c in enumerate(cols):
        col = colors[n % len(colors)]
        for k in range(result.aligned.count):
            shift = result.aligned.starts[k, c] if _travels(traj, c) else 0.0
            left.plot(phases, result.aligned.values[k, :, c] + shift, color=col, lw=0.6, alpha=0.45)
        left.plot(phases, closed[:, c], color=GREEN, lw=2.2)
    left.set_title("aligned cycles and the extracted loop (green)")
    left.set_xlabel("phase")
    right = fig.add_subplot(2, 2, 4)
    kt = result.aligned.knots_time
    rel = (kt - kt[:, :1]) / (kt[:, -1:] - kt[:, :1])
    for k in range(len(rel)):
        right.plot(result.aligned.knots_phase, rel[k], marker="o", ms=3, lw=0.8)
    right.plot([0, 1], [0, 1], color="grey", lw=0.6, ls=":")
    right.set_title(f"time alignment (spread {result.spread:.1%}, closure {result.closure_error:.1e})")
    right.set_xlabel("common phase")
    right.set_ylabel("phase in cycle")
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    plt.close(fig)
    return atomic_write_bytes(path, buf.getvalue())


def _travels(traj: Trajectory, column: int) -> bool:
    return any(it.kind == "position" and it.travel and it.start <= column < it.stop for it in traj.items)
