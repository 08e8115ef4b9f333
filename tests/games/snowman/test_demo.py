"""The shipped snowman demo replays headless to the end of the arc with every hash matching.

The recording (``games/snowman/demo.rec``, rewritten by ``puppetphone regen demos``)
holds only mouse input: three balls rolled, the middle lifted onto the bottom with the
stick, the head carried up and put on top; the snowman comes alive and itself rolls
two balls and stacks them into a second snowman.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from engine.app import App
from engine.statemachine import Brain
from games.snowman.components import Snowman, SnowmanStats
from tools.snowman_demo import DEMO_PATH
from games.snowman.rules import snowmen_standing
from input.recording import read_recording
from input.replay import verify


@pytest.fixture(scope="module")
def replayed() -> tuple[object, App, list[str]]:
    from puppetphone.games import make_app

    rec = read_recording(DEMO_PATH)
    assert rec.complete and rec.header.game == "snowman"
    apps: list[App] = []
    trace: list[str] = []

    def watch(app: App, i: int) -> None:
        if not apps:
            apps.append(app)
        n = len(app.world.query(Snowman))
        if not trace or trace[-1] != f"snowmen {n}":
            trace.append(f"snowmen {n}")

    result = verify(lambda hub: make_app("snowman", rec.header.seed, hub), rec, on_step=watch)
    return result, apps[0], trace


def test_every_hash_matches(replayed) -> None:
    result, _, _ = replayed
    assert result.ok, result.message
    assert result.frames > 60 * 30


def test_two_snowmen_stand_at_the_end_the_second_built_by_the_first(replayed) -> None:
    _, app, trace = replayed
    world = app.world
    assert world.resource(SnowmanStats).built == 2
    assert snowmen_standing(world) == 2
    assert trace == ["snowmen 0", "snowmen 1", "snowmen 2"]
    men = sorted((s.number, s.shape) for _, s in world.query(Snowman))
    assert men[0][1].middle is not None  # the first snowman is three balls
    assert men[1][1].middle is None and men[1][1].head <= 0.6 * men[1][1].bottom  # the second, two
    # Every puppet and snowman stands still on the ground, none is a ragdoll.
    assert all(brain.active == "Locomotion" for _, brain in world.query(Brain))


def test_play_replay_demo_headless_writes_the_last_frame(tmp_path: Path) -> None:
    shot = tmp_path / "last.png"
    done = subprocess.run(
        [sys.executable, "-m", "puppetphone", "play", "snowman", "--source", "replay:demo", "--headless",
         "--size", "320x180", "--screenshot", str(shot)],
        capture_output=True, text=True, timeout=600,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    assert "snowman 2 came alive" in done.stdout
    pixels = np.asarray(Image.open(shot).convert("RGB"), dtype=np.float64)
    assert pixels.shape == (180, 320, 3) and pixels.std() > 10.0  # a rendered scene, not a blank frame
