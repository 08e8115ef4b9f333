"""``puppetphone author flow`` and ``play snowman --flow`` as a user types them."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from authoring.flowcurves.storage import FORMAT, VERSION, load_flow
from engine.render.headless import egl_available
from games.snowman.bent_scenery import scenery_objects

needs_egl = pytest.mark.skipif(egl_available() is not None, reason=f"no EGL: {egl_available()}")


def puppetphone(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    exe = Path(sys.executable).with_name("puppetphone")
    cmd = [str(exe)] if exe.exists() else [sys.executable, "-m", "puppetphone"]
    env = {**os.environ, "SDL_VIDEODRIVER": "dummy", "XDG_DATA_HOME": str(cwd / "data")}
    return subprocess.run([*cmd, *args], cwd=cwd, env=env, capture_output=True, text=True, timeout=900)


def _bent_file(path: Path) -> Path:
    """A flow file whose first tree leans: every part above the ground shifted sideways with height."""
    objects = scenery_objects()
    for o in objects:
        if o["group"] == "tree0":
            for p in o["primitives"]:
                for end in ("a", "b"):
                    p[end][0] += 0.3 * p[end][1]
    doc = {
        "format": FORMAT,
        "version": VERSION,
        "scene": "snowman",
        "size": [1280, 720],
        "camera": {"target": [0, 0.8, 0], "yaw": 0.35, "pitch": 0.42, "distance": 17.0},
        "edits": [{"kind": "stroke", "points": [[0, 0], [10, 10]], "d_max": 60}],
        "objects": objects,
    }
    path.write_text(json.dumps(doc))
    return path


@needs_egl
def test_a_scripted_stroke_bends_trees_and_saves(tmp_path: Path) -> None:
    out, shot = tmp_path / "bent.flow.json", tmp_path / "after.png"
    rec = tmp_path / "row.rec"
    done = puppetphone("author", "flow", "snowman", "--headless", "--script", "row", "--frames", "70",
                       "--size", "1280x720", "-o", str(out), "--screenshot", str(shot), "--record", str(rec),
                       cwd=tmp_path)  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert "1 edits, 1 strokes, 1 clicks" in done.stdout
    doc = load_flow(out)
    assert [e["kind"] for e in doc["edits"]] == ["stroke"]
    rest = {o["name"]: o for o in scenery_objects()}
    moved = {
        o["group"]
        for o in doc["objects"]
        if np.abs(np.array(o["primitives"][0]["a"]) - rest[o["name"]]["primitives"][0]["a"]).max() > 0.05
    }
    assert {"tree0", "tree4"} <= moved  # the two back trees beside the stroke bend
    assert not any(g.startswith("rock") for g in moved)
    assert shot.stat().st_size > 10000
    # The recorded session replays: the scene rebuilt from the recording, the stroke repeated, every
    # step's edits and bent scenery matching (and a replay writes no file).
    out.unlink()
    again = puppetphone("replay", str(rec), "--verify", "--headless", cwd=tmp_path)
    assert again.returncode == 0, again.stdout + again.stderr
    assert "replayed 70 frames, all 70 state hashes match" in again.stdout and not out.exists()


@needs_egl
def test_the_bent_field_plays_and_replays_without_the_file(tmp_path: Path) -> None:
    flow = _bent_file(tmp_path / "lean.flow.json")
    done = puppetphone(
        "play", "snowman", "--flow", str(flow), "--headless", "--frames", "60", "--record", "bent.rec", cwd=tmp_path
    )
    assert done.returncode == 0, done.stderr
    flow.unlink()  # the recording's header carries the bent scenery
    again = puppetphone("replay", "bent.rec", "--verify", "--headless", cwd=tmp_path)
    assert again.returncode == 0, again.stderr + again.stdout


def test_a_bad_flow_file_is_one_line_and_nothing_runs(tmp_path: Path) -> None:
    bad = tmp_path / "bad.flow.json"
    bad.write_text('{"format": "puppetphone-flow", "version": 1, "scene": "snowman"}')
    done = puppetphone("play", "snowman", "--flow", str(bad), "--headless", "--frames", "5", cwd=tmp_path)
    assert done.returncode != 0
    assert len(done.stderr.strip().splitlines()) == 1 and "flow" in done.stderr
    other = _bent_file(tmp_path / "other.flow.json")
    doc = json.loads(other.read_text())
    doc["objects"] = doc["objects"][:-1]
    other.write_text(json.dumps(doc))
    done = puppetphone("play", "snowman", "--flow", str(other), "--headless", "--frames", "5", cwd=tmp_path)
    assert done.returncode != 0 and "not this field's" in done.stderr


def test_an_unknown_scene_is_a_clear_error(tmp_path: Path) -> None:
    done = puppetphone("author", "flow", "nowhere", "--headless", "--frames", "1", cwd=tmp_path)
    assert done.returncode == 2
    assert "neither a scene" in done.stderr
