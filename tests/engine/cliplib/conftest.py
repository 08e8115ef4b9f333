"""Fixtures: the CMU walk as a loop on the puppet (retargeted, extracted by the cycle tools)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from engine.clip import Clip


@pytest.fixture(scope="module")
def cmu_walk_loop() -> Clip:
    """CMU 16_15 retargeted to the puppet and cut to one loop, as ``cycle --retarget puppet`` does."""
    env = os.environ.get("PUPPETPHONE_DATA")
    found = [
        c
        for c in ([Path(env)] if env else []) + [Path(__file__).resolve().parents[4] / "shared" / "data"]
        if (c / "mocap").is_dir()
    ]
    if not found:
        pytest.skip("real mocap data not found: set PUPPETPHONE_DATA or put shared/data beside the project")
    d = found[0]
    from authoring.cycles.extract import extract_cycle
    from authoring.cycles.formats import load_performance, loop_clip
    from authoring.cycles.retarget_source import retarget_performance
    from engine.humanoid import humanoid_skeleton

    perf = retarget_performance(load_performance(Path(d) / "mocap" / "cmu_16_15_walk_daz.bvh"), humanoid_skeleton())
    result = extract_cycle(perf.trajectory, np.random.default_rng(0))
    return loop_clip(result, perf, "cmu walk")
