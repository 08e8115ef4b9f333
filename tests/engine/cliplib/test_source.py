"""``clips add`` reads a loop the project wrote as that loop, in every format, at its speed."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from authoring.cycles.extract import extract_cycle
from authoring.cycles.formats import load_performance, save_loop
from engine.cliplib.roles import check_role, conform
from engine.cliplib.source import read_motion
from engine.clips import default_clips
from engine.humanoid import humanoid_skeleton
from engine.io import clip_to_bvh, write_bvh
from engine.io.motion_file import to_puppet
from tests.engine.io.synthetic_bvh import blender_bvh, walk_take


def _take(path: Path, cycles: int = 5) -> Path:
    """The built-in walk performed ``cycles`` times at 30 fps: a BVH take."""
    return write_bvh(path, clip_to_bvh(walk_take(cycles)))


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


def test_a_closed_loop_exported_by_blender_stands_up_and_keeps_its_speed(tmp_path: Path) -> None:
    """Z up, six channels on loose bones, the first pose repeated at the end: a walk, standing, at its speed."""
    walk = default_clips()["walk"]
    n = round(walk.duration * 30.0)
    take = walk_take(2, fps=n / walk.duration)
    closed = replace(take, root=take.root[: n + 1], rotations=take.rotations[: n + 1])
    clip = read_motion(blender_bvh(tmp_path / "blender_loop.bvh", closed))
    assert clip.loop and clip.num_frames == n
    puppet, _ = to_puppet(clip)
    check_role(puppet, "walk", humanoid_skeleton())
    out = conform(puppet, "walk")
    assert out.average_speed() == pytest.approx(walk.average_speed(), rel=0.01)
    assert out.root[:, 1].min() > 0.7  # hips up, not lying on the floor
