"""The figure record every benchmark returns, and a median timer."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

__all__ = ["Figure", "median_time"]


@dataclass
class Figure:
    """One measured number, with the baseline it is compared to (DESIGN's JSON shape)."""

    bench: str
    name: str
    value: float
    unit: str
    baseline: str | None = None
    baseline_value: float | None = None

    @property
    def ratio(self) -> float | None:
        """``value / baseline_value`` when both exist."""
        if self.baseline_value in (None, 0) or self.value is None:
            return None
        return float(self.value) / float(self.baseline_value)

    def as_dict(self) -> dict[str, Any]:
        """The JSON object of ``bench --json``."""
        d = asdict(self)
        d["ratio"] = self.ratio
        return d

    def line(self) -> str:
        """One human-readable line: value, baseline and ratio."""
        s = f"{self.bench:>14}  {self.name:<34} {self.value:>12.4g} {self.unit:<6}"
        if self.baseline is not None:
            bv = "n/a" if self.baseline_value is None else f"{self.baseline_value:.4g}"
            r = "" if self.ratio is None else f"  ratio {self.ratio:.3g}"
            s += f"  vs {self.baseline}: {bv}{r}"
        return s


def median_time(
    fn: Callable[[], Any], repeats: int = 15, min_time: float = 0.05, clock: Callable[[], float] = time.process_time
) -> float:
    """Median seconds per call of ``fn`` over ``repeats`` samples, each at least ``min_time`` long.

    ``clock`` is the process's CPU time by default (every thread's: BLAS's and llvmpipe's workers
    count), which other people's load on a shared machine does not change, where wall time flips
    verdicts both ways; ``time.thread_time`` counts the calling thread alone."""
    fn()  # warm caches and lazy imports
    t0 = clock()
    fn()
    one = max(clock() - t0, 1e-7)
    inner = max(1, int(min_time / one))
    samples = []
    for _ in range(repeats):
        t0 = clock()
        for _ in range(inner):
            fn()
        samples.append((clock() - t0) / inner)
    return float(np.median(samples))
