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


def test_a_recording_with_a_malformed_tool_operation_is_refused_in_one_line(tmp_path: Path) -> None:
    from input.recording import Recorder
    from input.sample import TOOL, InputFrame

    done = puppetphone("author", "record", "--script", "loops", "--headless", "--frames", "20",
                       "--record", "take.rec", "-o", "loop.ppclip", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    rec = read_recording(tmp_path / "take.rec")
    with Recorder(tmp_path / "forged.rec", rec.header) as out:
        for i, (frame, digest, parts) in enumerate(zip(rec.frames, rec.hashes, rec.parts, strict=True)):
            if i == 5:
                frame = InputFrame(frame=frame.frame, events=((TOOL, '["zoom", "far"'),))
            out.write(frame, digest, parts)
    done = puppetphone("replay", "forged.rec", "--headless", cwd=tmp_path)
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert done.stderr.strip() == "error: forged.rec: step 5: malformed tool operation '[\"zoom\", \"far\"'"
    with Recorder(tmp_path / "short.rec", rec.header) as out:  # well-formed, but missing its arguments
        for i, (frame, digest, parts) in enumerate(zip(rec.frames, rec.hashes, rec.parts, strict=True)):
            out.write(InputFrame(frame=frame.frame, events=((TOOL, '["press"]'),)) if i == 3 else frame, digest, parts)
    done = puppetphone("replay", "short.rec", "--headless", cwd=tmp_path)
    assert done.returncode == 2 and done.stderr.strip().endswith("does not fit the record scene")
