"""Authored clips in the game: the CMU walk against the built-in walk, and the lookup cache.

* ``authored_start_cached_s`` — building the puppet's locomotion set from a library
  whose lookup measurement is cached (a second ``play --clips``), against measuring it
  (the first start);
* with the CMU 16_15 walk from ``../shared/data`` (when present), cut and added as
  ``cycle --retarget puppet`` and ``clips add`` do, the sandbox puppet walked by a
  scripted phone (:mod:`puppetphone.clip_walk`), against the built-in clips:

  - ``foot_slide_own_speed`` / ``speed_error_pct_own_speed`` — each set walked at its
    walk's own speed (1.11 and 1.3 m/s);
  - ``foot_slide_sweep_mean`` / ``speed_error_pct_sweep_max`` — both sets walked at the
    same stick speeds 0.6–1.5 m/s: the mean sliding and the worst speed error.
"""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from puppetphone.bench.figures import Figure

if TYPE_CHECKING:
    from engine.clip import Clip
    from puppetphone.clip_walk import WalkFigures

__all__ = ["run", "cmu_walk", "SWEEP"]

BENCH = "clips"
SWEEP = (0.6, 0.8, 0.9, 1.0, 1.1, 1.2, 1.3, 1.5)


def cmu_walk() -> Clip | None:
    """The CMU 16_15 walk as the library's walk (``None`` without the data)."""
    root = Path(os.environ.get("PUPPETPHONE_DATA", Path(__file__).resolve().parents[3] / "shared" / "data"))
    path = root / "mocap" / "cmu_16_15_walk_daz.bvh"
    if not path.is_file():
        return None
    from authoring.cycles.extract import extract_cycle
    from authoring.cycles.formats import load_performance, loop_clip
    from authoring.cycles.retarget_source import retarget_performance
    from engine.cliplib.roles import conform
    from engine.humanoid import humanoid_skeleton

    perf = retarget_performance(load_performance(path), humanoid_skeleton())
    return conform(loop_clip(extract_cycle(perf.trajectory, np.random.default_rng(0)), perf), "walk")


def _start_times(clips: dict) -> tuple[float, float]:
    from engine.cliplib.authored import AuthoredClips, authored_locomotion

    with tempfile.TemporaryDirectory() as cache:
        t0 = time.perf_counter()
        authored_locomotion(AuthoredClips(clips, Path(cache)))
        cold = time.perf_counter() - t0
        warm = []
        for _ in range(5):
            t0 = time.perf_counter()
            authored_locomotion(AuthoredClips(clips, Path(cache)))
            warm.append(time.perf_counter() - t0)
    return float(np.median(warm)), cold


def _walk(speed: float, clips: dict | None) -> WalkFigures:
    from puppetphone.clip_walk import record_stick_walk, walk_figures

    with tempfile.TemporaryDirectory() as d:
        rec = record_stick_walk(Path(d) / "walk.rec", speed=speed, clips=clips)
        return walk_figures(rec)


def run() -> list[Figure]:
    """Measure and return the figures."""
    from engine.cliplib.embed import encode
    from engine.clips import default_clips

    walk = cmu_walk()
    authored = {"walk": walk if walk is not None else default_clips()["walk"].resampled(50.0)}
    warm, cold = _start_times(authored)
    figs = [Figure(BENCH, "authored_start_cached_s", warm, "s", "measuring the lookup (first start)", cold)]
    if walk is None:
        return figs
    payload = encode(authored)
    own_a = _walk(walk.average_speed(), payload)
    own_b = _walk(default_clips()["walk"].average_speed(), None)
    figs += [
        Figure(BENCH, "foot_slide_own_speed", own_a.foot_slide, "m/s", "built-in walk", own_b.foot_slide),
        Figure(BENCH, "speed_error_pct_own_speed", own_a.speed_error_pct, "%", "built-in walk", own_b.speed_error_pct),
    ]
    sweep_a = [_walk(v, payload) for v in SWEEP]
    sweep_b = [_walk(v, None) for v in SWEEP]
    figs += [
        Figure(
            BENCH,
            "foot_slide_sweep_mean",
            float(np.mean([f.foot_slide for f in sweep_a])),
            "m/s",
            "built-in walk",
            float(np.mean([f.foot_slide for f in sweep_b])),
        ),
        Figure(
            BENCH,
            "speed_error_pct_sweep_max",
            max(f.speed_error_pct for f in sweep_a),
            "%",
            "built-in walk",
            max(f.speed_error_pct for f in sweep_b),
        ),
    ]
    for v, a, b in zip(SWEEP, sweep_a, sweep_b, strict=True):
        figs.append(
            Figure(BENCH, f"foot_slide_at_{round(v * 10):02d}dms", a.foot_slide, "m/s", "built-in walk", b.foot_slide)
        )
    return figs
