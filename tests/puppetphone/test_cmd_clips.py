"""``puppetphone clips``: add / list / remove as a user types them; refusals in one line with exit 2."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from engine.clipfile import save_clip
from engine.clips import default_clips


def _pp(*args: str, cwd: Path, env: dict[str, str] | None = None) -> subprocess.CompletedProcess[str]:
    e = dict(os.environ, XDG_DATA_HOME=str(cwd / "data"), XDG_CACHE_HOME=str(cwd / "cache"), **(env or {}))
    return subprocess.run(
        [sys.executable, "-m", "puppetphone", *args], capture_output=True, text=True, cwd=cwd, env=e, timeout=300
    )


@pytest.fixture
def clips(tmp_path: Path) -> Path:
    """A built-in walk (50 fps: a clip of its own) and the built-in idle as files."""
    save_clip(default_clips()["walk"].resampled(50.0), tmp_path / "walk.ppclip")
    save_clip(default_clips()["idle"], tmp_path / "idle.ppclip")
    return tmp_path


def test_add_list_remove_in_the_default_library(clips: Path) -> None:
    out = _pp("clips", "list", cwd=clips)
    assert out.returncode == 0 and "no clips; the built-in clips play" in out.stdout
    out = _pp("clips", "add", "walk.ppclip", "--role", "walk", cwd=clips)
    assert out.returncode == 0, out.stderr
    assert "added walk.ppclip as the walk" in out.stdout
    assert (clips / "data" / "puppetphone" / "clips" / "walk.ppclip").is_file()
    out = _pp("clips", "list", cwd=clips)
    assert "walk" in out.stdout and "1.30 m/s" in out.stdout and "from walk.ppclip" in out.stdout
    out = _pp("clips", "add", "walk.ppclip", "--role", "walk", cwd=clips)
    assert out.returncode == 0 and "replaced the walk that came from walk.ppclip" in out.stdout
    out = _pp("clips", "remove", "walk", cwd=clips)
    assert out.returncode == 0 and "the built-in walk plays it" in out.stdout
    out = _pp("clips", "remove", "walk", cwd=clips)
    assert out.returncode == 2 and "has no walk" in out.stderr


@pytest.mark.parametrize(
    ("file", "role", "reason"),
    [
        ("idle.ppclip", "walk", "refused as the walk: a walk moves at 0.5–2.2 m/s; 'idle' has no forward speed"),
        ("walk.ppclip", "crouch walk", "refused as the crouch walk: a crouch_walk is crouched and 'walk' is standing"),
        ("missing.bvh", "walk", "clips: no such file: missing.bvh"),  # the file named once
        ("walk.ppclip", "../evil", "is not a name"),
    ],
)
def test_refusals_say_why_in_one_line(clips: Path, file: str, role: str, reason: str) -> None:
    out = _pp("clips", "add", file, "--role", role, "--clips", "lib", cwd=clips)
    assert out.returncode == 2
    assert reason in out.stderr and len(out.stderr.strip().splitlines()) == 1, out.stderr
    assert not (clips / "lib" / "clips.json").exists()


def test_play_refuses_a_damaged_library_in_one_line(clips: Path) -> None:
    (clips / "lib").mkdir()
    (clips / "lib" / "clips.json").write_text("{not json")
    out = _pp(
        "play",
        "sandbox",
        "--headless",
        "--frames",
        "2",
        "--clips",
        "lib",
        "--source",
        "osc",
        "--osc-port",
        "0",
        cwd=clips,
        env={"SDL_VIDEODRIVER": "dummy", "SDL_AUDIODRIVER": "dummy"},
    )
    assert out.returncode == 2 and "clips.json is not valid JSON" in out.stderr
    assert len(out.stderr.strip().splitlines()) == 1, out.stderr


def test_play_with_an_empty_library_plays_the_built_in_clips(clips: Path) -> None:
    out = _pp(
        "play",
        "sandbox",
        "--headless",
        "--frames",
        "2",
        "--clips",
        "nowhere",
        "--source",
        "osc",
        "--osc-port",
        "0",
        "--record",
        "s.rec",
        cwd=clips,
        env={"SDL_VIDEODRIVER": "dummy", "SDL_AUDIODRIVER": "dummy"},
    )
    assert out.returncode == 0, out.stderr
    assert "empty or missing; the built-in clips play" in out.stderr
    from input.recording import read_recording

    assert "clips" not in read_recording(clips / "s.rec").header.setup
