"""Fuzzing performances read by ``puppetphone cycle``: ``.npz`` and CSV, by byte mutation.

Allowed outcomes: a performance whose trajectory is finite and within its bounds, or a
``TrajectoryError``. Never another exception, a hang or a large allocation.
"""

from __future__ import annotations

import io

import numpy as np
import pytest

from authoring.cycles.formats import load_performance
from authoring.cycles.trajectory import MAX_MAGNITUDE, TrajectoryError

pytestmark = pytest.mark.fuzz


def _check(path):  # type: ignore[no-untyped-def]
    perf = load_performance(path)
    v = perf.trajectory.values
    assert np.isfinite(v).all() and np.abs(v).max() <= MAX_MAGNITUDE


def _performance() -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(40) / 30.0
    return t, np.column_stack([np.sin(t * 3), np.cos(t * 3), np.ones(40), np.zeros(40), np.zeros(40), np.zeros(40)])


@pytest.mark.parametrize("compressed", [False, True])
def test_fuzz_npz_performances(campaign, mutations, fuzz_budget, tmp_path, compressed):
    t, v = _performance()
    buf = io.BytesIO()
    (np.savez_compressed if compressed else np.savez)(
        buf, times=t, values=v, names=np.array(["a.x", "a.y", "a.z", "s", "u", "w"])
    )
    cases, seed = fuzz_budget(1000)
    c = campaign(TrajectoryError)
    path = tmp_path / "m.npz"
    for data in mutations(buf.getvalue(), cases, seed):
        path.write_bytes(data)
        c.run(_check, path)
    c.check(f"npz ({'compressed' if compressed else 'stored'})")


def test_fuzz_csv_performances(campaign, mutations, fuzz_budget, tmp_path):
    t, v = _performance()
    text = "time,a.x,a.y,a.z,s,u,w\n" + "".join(
        ",".join(repr(float(x)) for x in [ti, *row]) + "\n" for ti, row in zip(t, v, strict=True)
    )
    cases, seed = fuzz_budget(1200)
    c = campaign(TrajectoryError)
    path = tmp_path / "m.csv"
    for data in mutations(text.encode(), cases, seed):
        path.write_bytes(data)
        c.run(_check, path)
    c.check("csv")
