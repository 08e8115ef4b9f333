"""The shipped demo replays headless: every stage is reached, in order, and every hash matches."""

from __future__ import annotations

from pathlib import Path

import pytest

from input.recording import read_recording
from input.replay import verify

DEMO = Path(__file__).resolve().parents[3] / "games" / "tasbada" / "demo.rec"


def test_demo_replays_every_stage_in_order_with_matching_hashes(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from puppetphone.games import make_app

    rec = read_recording(DEMO)
    assert rec.complete and rec.header.game == "tasbada"
    # The recorded setup, saving to a file of the test's (a replay itself saves nowhere).
    setup = {**rec.header.setup, "save_to": str(tmp_path / "save.json")}
    result = verify(lambda hub: make_app("tasbada", rec.header.seed, hub, setup), rec)
    assert result.ok, result.message()
    lines = [ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("stage: ")]
    assert lines == ["stage: real", "stage: props alive", "stage: mixed", "stage: virtual"]
    # The journey was saved as it went (atomically), and names every stage.
    from games.tasbada.save import load_progress

    progress = load_progress(tmp_path / "save.json")
    assert progress is not None and progress.reached == ["real", "props alive", "mixed", "virtual"]
    assert len(progress.marks) == 3 and progress.marks[1].kind == "lasso"


def test_a_headless_replay_screenshot_shows_the_living_props_and_exits_cleanly(tmp_path: Path) -> None:
    """Frame 700 is in stage 2: the jug talks. The props are cut out on a worker thread; a headless frame
    waits for them (it used to show the photo alone, and the process aborted with 134 on exit)."""
    import os
    import subprocess
    import sys

    import numpy as np
    from PIL import Image

    from engine.render.headless import egl_available

    if egl_available() is not None:
        pytest.skip(f"no EGL: {egl_available()}")
    env = {**os.environ, "SDL_VIDEODRIVER": "dummy", "XDG_DATA_HOME": str(tmp_path / "data")}
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "puppetphone",
            "replay",
            str(DEMO),
            "--headless",
            "--frames",
            "701",
            "--screenshot",
            "s.png",
            "--screenshot-at",
            "700",
        ],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    shot = np.asarray(Image.open(tmp_path / "s.png").convert("RGB"), dtype=np.int32)
    h, w = shot.shape[:2]
    jug = shot[int(0.5 * h) : int(0.85 * h), int(0.45 * w) : int(0.7 * w)]
    pupils_and_mouth = (jug < 70).all(axis=2)  # the photo's orange jug has no near-black pixel; the living one a face
    assert pupils_and_mouth.sum() > 300, f"no living jug: {pupils_and_mouth.sum()} face pixels"
    banner = shot[int(0.9 * h) : int(0.96 * h), int(0.1 * w) : int(0.8 * w)]
    assert banner.mean() > 85, "the 'waking up the things you marked' banner darkens the floor"
