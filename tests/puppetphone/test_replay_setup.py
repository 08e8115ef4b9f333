"""A recording's set-up is outside input: crafted values are one line and exit 2, never a traceback,
never gigabytes, and never a file opened on the replaying person's disk."""

from __future__ import annotations

import base64
import json
import struct
import tracemalloc
import zlib
from dataclasses import asdict
from pathlib import Path
from typing import Any

import pytest

from input.recording import MAGIC, RecordingHeader
from puppetphone.cli import main


def _crafted(path: Path, game: str, setup: Any) -> Path:
    """A finished recording with no frames whose header carries ``setup`` as given (its checksum fixed)."""
    head = asdict(RecordingHeader(game=game, seed=1, dt=1 / 60))
    head["setup"] = setup
    raw = json.dumps(head, sort_keys=True).encode()
    path.write_bytes(MAGIC + struct.pack("<II", len(raw), zlib.crc32(raw)) + raw + struct.pack("<II", 0, 0))  # closed
    return path


CASES = [
    ("snowman", {"flow": "x"}, "flow"),
    ("snowman", {"flow": [[1]]}, "flow"),
    ("tasbada", {"marks": 5}, "marks"),
    ("tasbada", {"reached": None}, "reached"),
    ("tasbada", {"ground_v": [1, 2]}, "floor line"),
    ("tasbada", {"pose_aspect": {"a": 1}}, "pose_aspect"),
    ("tasbada", {"photo": [1, 2]}, None),  # a recorded path is never opened: the shipped photo shows
    ("sandbox", {"scene": [1, 2]}, "scene"),
    ("sandbox", {"puppets": None}, "puppets"),
    (
        "author-record",
        {"item": "hips", "drive": "rotation", "countdown": 1e308, "seconds": 8.0, "seed": 0},
        "countdown",
    ),
    ("author-record", {"item": 5}, "item"),
]


@pytest.mark.parametrize("game,setup,says", CASES)
def test_a_crafted_setup_is_one_line_not_a_traceback(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], game: str, setup: Any, says: str | None
) -> None:
    code = main(["replay", str(_crafted(tmp_path / "c.rec", game, setup)), "--headless", "--frames", "2"])
    err = capsys.readouterr().err
    if says is None:
        assert code in (0, 1) and "Traceback" not in err
        return
    assert code == 2 and says in err and len([ln for ln in err.splitlines() if ln.startswith("error")]) == 1


def test_a_setup_that_is_not_an_object_is_a_recording_error(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["replay", str(_crafted(tmp_path / "c.rec", "snowman", [1, 2])), "--headless"]) == 2
    assert "setup must be an object" in capsys.readouterr().err


def test_a_replay_never_opens_a_clip_the_header_names(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from engine.clipfile import save_clip
    from engine.clips import default_clips

    victim = save_clip(default_clips()["walk"], tmp_path / "private.ppclip")
    rec = _crafted(tmp_path / "c.rec", "author-edit", {"clip": str(victim), "size": [64, 64], "ppclip": "", "side": ""})
    opened: list[str] = []
    import builtins
    import os

    real_open, real_os_open = builtins.open, os.open
    spy = pytest.MonkeyPatch()
    spy.setattr(builtins, "open", lambda f, *a, **k: (opened.append(str(f)), real_open(f, *a, **k))[1])
    spy.setattr(os, "open", lambda f, *a, **k: (opened.append(str(f)), real_os_open(f, *a, **k))[1])
    try:
        code = main(["replay", str(rec), "--headless", "--frames", "2"])
    finally:
        spy.undo()
    assert code == 2 and "without carrying it" in capsys.readouterr().err
    assert str(victim) not in opened


def test_embedded_clips_beyond_the_set_limit_are_refused_before_decoding(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """64 clips of 100,000 frames each, within the per-clip limits: 4.6 GB decoded on the old code."""
    from engine.cliplib import embed

    data = base64.b64encode(zlib.compress(bytes(100_000 * 87 * 8), 9)).decode()
    clips = {
        f"walk_{i}": {
            "name": f"c{i}",
            "fps": 60,
            "loop": True,
            "markers": {},
            "frames": 100_000,
            "root_motion": True,
            "data": data,
        }
        for i in range(64)
    }
    setup = {"clips": {"sha256": embed._payload_digest(clips), "clips": clips}}
    rec = _crafted(tmp_path / "c.rec", "sandbox", setup)
    tracemalloc.start()
    try:
        code = main(["replay", str(rec), "--headless", "--frames", "2"])
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert code == 2 and "limit" in capsys.readouterr().err
    assert peak < 200 << 20
