"""``clips add`` reads a loop the project wrote as that loop, in every format, at its speed."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from authoring.cycles.extract import extract_cycle
from authoring.cycles.formats import load_performance, save_loop
from engine.clip import Clip
from engine.clips import default_clips
from engine.cliplib.roles import check_role, conform
from engine.cliplib.source import read_motion
from engine.humanoid import humanoid_skeleton
from engine.io import clip_to_bvh, write_bvh


def _take(path: Path, cycles: int = 5, fps: float = 30.0) -> Path:
    """The built-in walk performed ``cycles`` times at ``fps``, its travel in the root: a BVH take."""
    walk = default_clips()["walk"]
    t = np.arange(int(cycles * walk.duration * fps)) / fps
    pose = walk.sample(t)
    travel = np.array([walk.sample_root_motion(float(x))[0] for x in t])
    take = Clip("take", walk.skeleton, fps, pose.root + travel, pose.rotations)
    return write_bvh(path, clip_to_bvh(take))


@pytest.fixture(scope="module")
def loops(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """The loop ``cycle`` extracts from a 30 fps take, written as BVH (closed), glTF and ppclip."""
    d = tmp_path_factory.mktemp("loops")
    perf = load_performance(_take(d / "take.bvh"))
    result = extract_cycle(perf.trajectory, np.random.default_rng(0))
    return {ext: save_loop(result, perf, d / f"loop.{ext}") for ext in ("bvh", "glb", "ppclip")}


def test_the_projects_own_bvh_loop_reads_as_a_loop_like_its_glb_and_ppclip(loops: dict[str, Path]) -> None:
    clips = {ext: read_motion(path) for ext, path in loops.items()}
    assert all(c.loop for c in clips.values())
    speeds = {}
    for ext, clip in clips.items():
        check_role(clip, "walk", humanoid_skeleton())
        speeds[ext] = conform(clip, "walk").average_speed()
    assert speeds["bvh"] == pytest.approx(speeds["ppclip"], rel=0.01)
    assert speeds["glb"] == pytest.approx(speeds["ppclip"], rel=0.01)
    assert speeds["ppclip"] == pytest.approx(default_clips()["walk"].average_speed(), rel=0.01)


def test_a_take_is_still_no_loop(tmp_path: Path) -> None:
    assert not read_motion(_take(tmp_path / "take.bvh", cycles=3)).loop
