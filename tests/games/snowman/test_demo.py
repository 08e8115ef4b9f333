"""The shipped snowman demo replays headless to the end of the arc with every hash matching.

The recording (``games/snowman/demo.rec``, rewritten by ``python -m tools.regen demos``)
holds only mouse input: three balls rolled, the middle lifted onto the bottom with the
stick, the head carried up and put on top; the snowman comes alive and itself rolls
two balls and stacks them into a second snowman.

It is the longest replay of the suite (4,666 steps, over a minute), so it runs **once**: the
``replay --verify --headless --screenshot`` command, as a user types it, in this process, with
the steps observed; every test below reads that one run (the command's exit code and verdict,
what the game printed, the final world, the screenshot). ``tests/puppetphone/test_replay_cmd.py``
leaves this file out of its every-shipped-recording check for that reason.
"""

from __future__ import annotations

import contextlib
import io
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from engine.app import App
from engine.statemachine import Brain
from games.snowman.components import Snowman, SnowmanStats
from games.snowman.rules import snowmen_standing
from input.recording import read_recording
from tools.snowman_demo import DEMO_PATH


@dataclass
class DemoRun:
    code: int
    out: str
    err: str
    shot: Path
    frames: int
    app: App | None = None
    trace: list[str] = field(default_factory=list)


@pytest.fixture(scope="module")
def demo(tmp_path_factory: pytest.TempPathFactory) -> DemoRun:
    """One replay of the demo through ``puppetphone replay``, watching each step of the app it builds."""
    from puppetphone.cli import main

    rec = read_recording(DEMO_PATH)
    assert rec.complete and rec.header.game == "snowman"
    shot = tmp_path_factory.mktemp("demo") / "last.png"
    run = DemoRun(0, "", "", shot, len(rec))
    step = App.step

    def watched(app: App) -> None:
        step(app)
        run.app = app
        n = len(app.world.query(Snowman))
        if not run.trace or run.trace[-1] != f"snowmen {n}":
            run.trace.append(f"snowmen {n}")

    out, err = io.StringIO(), io.StringIO()
    with pytest.MonkeyPatch.context() as mp, contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        mp.setattr(App, "step", watched)
        run.code = main(
            ["replay", str(DEMO_PATH), "--verify", "--headless", "--size", "320x180", "--screenshot", str(shot)]
        )
    run.out, run.err = out.getvalue(), err.getvalue()
    return run


def test_every_hash_matches(demo: DemoRun) -> None:
    assert demo.code == 0, demo.out[-2000:] + demo.err[-2000:]
    assert demo.frames > 60 * 30
    assert f"replayed {demo.frames} frames, all {demo.frames} state hashes match" in demo.out


def test_two_snowmen_stand_at_the_end_the_second_built_by_the_first(demo: DemoRun) -> None:
    assert demo.app is not None
    world = demo.app.world
    assert world.frame == demo.frames
    assert world.resource(SnowmanStats).built == 2
    assert snowmen_standing(world) == 2
    assert demo.trace == ["snowmen 0", "snowmen 1", "snowmen 2"]
    assert "snowman 1 came alive (3 balls" in demo.out and "snowman 2 came alive (2 balls" in demo.out
    men = sorted((s.number, s.shape) for _, s in world.query(Snowman))
    assert men[0][1].middle is not None  # the first snowman is three balls
    assert men[1][1].middle is None and men[1][1].head <= 0.6 * men[1][1].bottom  # the second, two
    # Every puppet and snowman stands still on the ground, none is a ragdoll.
    assert all(brain.active == "Locomotion" for _, brain in world.query(Brain))


def test_the_replay_writes_the_last_frame(demo: DemoRun) -> None:
    assert f"screenshot: {demo.shot}" in demo.out
    with Image.open(demo.shot) as image:
        pixels = np.asarray(image.convert("RGB"), dtype=np.float64)
    assert pixels.shape == (180, 320, 3) and pixels.std() > 10.0  # a rendered scene, not a blank frame


def test_play_replay_demo_names_the_shipped_recording(tmp_path: Path) -> None:
    """``play snowman --source replay:demo`` finds and plays the shipped file (its first second: the whole
    replay is checked above), in a fresh interpreter as a user types it."""
    shot = tmp_path / "first.png"
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "puppetphone",
            "play",
            "snowman",
            "--source",
            "replay:demo",
            "--headless",
            "--frames",
            "60",
            "--size",
            "160x90",
            "--screenshot",
            str(shot),
        ],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    assert "ran 60 steps of snowman" in done.stdout, done.stdout
    with Image.open(shot) as image:
        assert image.size == (160, 90)
