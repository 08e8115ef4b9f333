"""``author edit`` on a motion file: a closed loop opens as itself, a refused take names the part that loops."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from authoring.motion_loop import open_loop
from engine import quat
from engine.clip import Clip
from engine.io import clip_to_bvh, write_bvh
from tests.engine.io.synthetic_bvh import walk_take


def test_a_refused_take_names_the_part_that_loops(tmp_path: Path) -> None:
    """Five strides, then five seconds of wandering: as a whole no loop, but its start loops (as `cycle` says)."""
    walk = walk_take(5, 30.0)
    rng = np.random.default_rng(0)
    n = 150
    drift = 0.03 * np.cumsum(rng.standard_normal((n, *walk.rotations.shape[1:])), axis=0)
    rot = np.concatenate([walk.rotations, quat.normalize(walk.rotations[-1] + drift)])
    root = np.concatenate([walk.root, walk.root[-1] + np.cumsum(0.02 * rng.standard_normal((n, 3)), axis=0)])
    path = write_bvh(tmp_path / "mixed.bvh", clip_to_bvh(Clip("mixed", walk.skeleton, 30.0, root, rot)))
    with pytest.raises(ValueError, match=r"loop with period 1\.\d+ s .*; try --start 0 --end"):
        open_loop(path)


def test_a_closed_bvh_loop_opens_as_that_loop(tmp_path: Path) -> None:
    take = walk_take(2, 30.0)
    n = take.num_frames // 2
    closed = replace(take, root=take.root[: n + 1], rotations=take.rotations[: n + 1])
    loop, note = open_loop(write_bvh(tmp_path / "loop.bvh", clip_to_bvh(closed)))
    assert loop.loop and loop.num_frames == n and "a seamless loop of" in note
