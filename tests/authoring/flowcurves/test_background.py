"""SEcurves found in another process: the same ones as in-process, with progress, and a session made from them."""

from __future__ import annotations

import time

import numpy as np
import pytest

from authoring.flowcurves.background import BackgroundSession
from authoring.flowcurves.session import FlowSession

from .conftest import tree_scene


@pytest.mark.slow  # the tree's SEcurve search in a child process
def test_the_background_search_finds_the_same_securves_and_reports_progress(tree_securves):
    scene = tree_scene()
    seen = []
    building = BackgroundSession(scene, lambda found: FlowSession(scene, securves=found))
    deadline = time.monotonic() + 120
    while not building.done():
        assert time.monotonic() < deadline, "the SEcurve search did not finish"
        seen.append(building.text)
        time.sleep(0.05)
    session = building.result()
    assert any("finding SEcurves: 1/" in t for t in seen)  # the window had its progress to show
    assert len(session.auto_securves) == len(tree_securves)
    for a, b in zip(session.auto_securves, tree_securves, strict=True):
        assert np.array_equal(a.points, b.points)  # bit for bit: a replay finds them in-process
