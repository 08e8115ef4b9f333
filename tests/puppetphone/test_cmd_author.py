"""``puppetphone author record``: a take at real tempo, recorded and replayed through the CLI."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from engine.clipfile import load_clip
from input.recording import read_recording


def puppetphone(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "SDL_VIDEODRIVER": "dummy"}
    return subprocess.run([sys.executable, "-m", "puppetphone", *args], cwd=cwd, env=env, capture_output=True,
                          text=True, timeout=600)


def test_a_recorded_take_replays_to_the_same_loop_without_writing(tmp_path: Path) -> None:
    done = puppetphone("author", "record", "--script", "loops", "--headless", "--frames", "600", "--countdown", "1",
                       "--seconds", "6", "--record", "take.rec", "-o", "loop.ppclip", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    loop = load_clip(tmp_path / "loop.ppclip")
    assert loop.loop and loop.num_frames > 10  # the scripted performer's take became a clean loop
    header = read_recording(tmp_path / "take.rec").header
    assert header.game == "author-record" and header.setup["item"] == "r_upper_arm"
    (tmp_path / "loop.ppclip").unlink()
    done = puppetphone("replay", "take.rec", "--verify", "--headless", cwd=tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "replayed 600 frames, all 600 state hashes match" in done.stdout
    assert not (tmp_path / "loop.ppclip").exists()  # a replay saves nothing


def test_a_take_of_another_tempo_is_a_divergence(tmp_path: Path) -> None:
    """The recording pins the take: replayed with a shorter countdown the state differs, and says where."""
    done = puppetphone("author", "record", "--script", "loops", "--headless", "--frames", "120", "--countdown", "1",
                       "--record", "take.rec", "-o", "loop.ppclip", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    from input.recording import Recorder

    rec = read_recording(tmp_path / "take.rec")
    rec.header.setup["countdown"] = 0.5
    with Recorder(tmp_path / "edited.rec", rec.header) as out:
        for frame, digest, parts in zip(rec.frames, rec.hashes, rec.parts, strict=True):
            out.write(frame, digest, parts)
    done = puppetphone("replay", "edited.rec", "--headless", cwd=tmp_path)
    assert done.returncode == 1
    assert "differs at frame 0 in scene " in done.stdout  # the countdown timer is the first thing that differs
