"""``author edit`` opens BVH, glTF and GLB (issue 24 item 1), PuppetPhone's own exports included."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from authoring.motion_loop import open_loop
from engine.clips import default_clips
from engine.io.bvh import write_bvh
from engine.io.bvh_convert import clip_to_bvh
from engine.io.gltf_write import write_gltf
from engine.io.loop_export import closed
from tests.engine.io.synthetic_bvh import human_bvh


def _edit(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "SDL_VIDEODRIVER": "dummy", "SDL_AUDIODRIVER": "dummy"}
    return subprocess.run(
        [sys.executable, "-m", "puppetphone", "author", "edit", *args, "--headless", "--frames", "10"],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )


def test_author_edit_opens_a_bvh_and_a_glb(mocap_dir: Path, tmp_path: Path) -> None:
    r = _edit(str(mocap_dir / "cmu_16_15_walk_daz.bvh"), "--screenshot", "bvh.png", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "extracted a 1.1" in r.stderr and (tmp_path / "bvh.png").stat().st_size > 10_000
    r = _edit(
        str(mocap_dir / "Fox.glb"),
        "--animation",
        "Walk",
        "--screenshot",
        "fox.png",
        "--record",
        "fox.rec",
        cwd=tmp_path,
    )
    assert r.returncode == 0, r.stderr
    assert "a seamless loop of 17 frames" in r.stderr
    env = {**os.environ, "SDL_VIDEODRIVER": "dummy"}
    again = subprocess.run(
        [sys.executable, "-m", "puppetphone", "replay", "fox.rec", "--verify", "--headless"],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert again.returncode == 0, again.stdout + again.stderr  # the opened loop rides in the recording


def test_our_own_exports_open_as_the_loop_they_are(tmp_path: Path) -> None:
    walk = default_clips()["walk"]
    write_bvh(tmp_path / "walk.bvh", clip_to_bvh(closed(walk)))
    write_gltf(tmp_path / "walk.glb", walk)
    for name in ("walk.bvh", "walk.glb"):
        clip, note = open_loop(tmp_path / name)
        assert "loop of" in note and clip.loop and clip.num_frames == walk.num_frames
    r = _edit("walk.glb", cwd=tmp_path)
    assert r.returncode == 0, r.stderr


def test_retarget_and_bad_options(tmp_path: Path) -> None:
    (tmp_path / "bio.bvh").write_text(human_bvh())
    clip, note = open_loop(tmp_path / "bio.bvh", retarget=True)
    assert "retargeted to the puppet with the 'cmu_mixamo' map" in note
    assert clip.skeleton.names == default_clips()["walk"].skeleton.names
    r = _edit("walk", "--animation", "Walk", cwd=tmp_path)
    assert r.returncode == 2 and "only apply to a BVH/glTF/GLB file" in r.stderr
    r = _edit("bio.bvh", "--animation", "Walk", cwd=tmp_path)
    assert r.returncode == 2 and "--animation is for glTF" in r.stderr
    with pytest.raises(ValueError):
        open_loop(tmp_path / "bio.bvh", units="furlong")
