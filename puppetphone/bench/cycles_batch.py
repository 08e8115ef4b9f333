"""``puppetphone bench cycles-batch``: takes per second through ``puppetphone cycles``, against a shell loop.

The same 40 synthetic takes (:func:`write_takes`: one activity repeated, three activities
in a row, and takes that never repeat) go through:

* the baseline: ``puppetphone cycle TAKE -o LOOP`` once per take, one process each (the
  shell loop a library needed before), timed per take; its rate is one over the median;
* ``cycles_per_s_serial`` — ``puppetphone cycles DIR -o LIB --jobs 1``;
* ``cycles_per_s_pool2`` — the same with ``--jobs 2`` (a process pool of two);
* ``cycles_per_s_dask2`` — the same with ``--scheduler`` on a ``LocalCluster`` of two
  single-threaded worker processes started beforehand (skipped without the ``cluster`` extra).

Each batch figure is the median over :data:`REPEATS` runs into a fresh library, start-up
included (a user pays it). These rates are timed on the wall clock, as the latency figures are: a rate of
takes through a pool of processes is what the pool is for, and CPU time would count its two
workers' seconds as one user's wait (read them on a quiet machine: other load moves both sides).
A "cycle" here is a take processed: looped or refused; the batch also searches every take for
several activities, which the baseline does not.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from puppetphone.bench.figures import Figure

__all__ = ["TAKES", "run", "write_takes"]

BENCH = "cycles-batch"
TAKES = 40
REPEATS = 3
BASELINE = "one process per take, puppetphone cycle (straw man)"


def write_takes(folder: Path, count: int = TAKES, seed: int = 0) -> list[Path]:
    """``count`` synthetic takes as ``.npz``, sized like mocap (120 fps, 60–240 dims, 4–11 s).

    Most repeat one activity; every 8th has three activities in a row; every 8th never
    repeats (a random walk), so the batch refuses some.
    """
    from authoring.cycles.synthetic import make_performance, mixed_take

    rng = np.random.default_rng(seed)
    folder.mkdir(parents=True, exist_ok=True)
    paths = []
    for i in range(count):
        if i % 8 == 7:
            values = np.cumsum(rng.normal(size=(1200, 60)), axis=0)
        elif i % 8 == 3:
            values = mixed_take(60, rng, fps=120.0)[0].values
        else:
            dims = (60, 120, 175, 240)[i % 4]
            values = make_performance(
                dims, rng, cycles=int(rng.integers(5, 9)), period=float(rng.uniform(0.7, 1.4)), fps=120.0
            ).trajectory.values
        path = folder / f"take_{i:03d}.npz"
        np.savez(path, values=values, fps=np.float64(120.0))
        paths.append(path)
    return paths


def _cli(*args: str) -> float:
    t0 = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "puppetphone", *args], check=False, capture_output=True, text=True)
    if done.returncode not in (0, 3):
        raise RuntimeError(f"puppetphone {' '.join(args)} failed: {done.stderr.strip()[-300:]}")
    return time.perf_counter() - t0


def _batch_rate(src: Path, work: Path, extra: list[str]) -> float:
    times = []
    for r in range(REPEATS):
        lib = work / f"lib_{'_'.join(extra).replace(':', '').replace('/', '')}_{r}"
        times.append(_cli("cycles", str(src), "-o", str(lib), "--no-progress", *extra))
    return TAKES / float(np.median(times))


def run() -> list[Figure]:
    """Measure and return the figures."""
    with tempfile.TemporaryDirectory(prefix="bench-cycles-") as tmp:
        work = Path(tmp)
        takes = write_takes(work / "takes")
        per_take = [_cli("cycle", str(p), "-o", str(work / "loop.npz")) for p in takes]
        baseline = 1.0 / float(np.median(per_take))
        figs = [Figure(BENCH, "cycles_per_s_cli_loop", baseline, "takes/s")]
        for name, extra in (("serial", ["--jobs", "1"]), ("pool2", ["--jobs", "2"])):
            figs.append(
                Figure(
                    BENCH,
                    f"cycles_per_s_{name}",
                    _batch_rate(work / "takes", work, extra),
                    "takes/s",
                    BASELINE,
                    baseline,
                )
            )
        dask = _dask_rate(work)
        if dask is not None:
            figs.append(Figure(BENCH, "cycles_per_s_dask2", dask, "takes/s", BASELINE, baseline))
    return figs


def _dask_rate(work: Path) -> float | None:
    try:
        from distributed import LocalCluster
    except ImportError:
        print("cycles_per_s_dask2 skipped: Dask's distributed is not installed (the 'cluster' extra)", file=sys.stderr)
        return None
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        return _batch_rate(work / "takes", work, ["--scheduler", cluster.scheduler_address])
