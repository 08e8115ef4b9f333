"""The web controller in a real browser: headless Chromium grabs and moves the puppet of a headless game.

``puppetphone play sandbox --source web --record`` runs as a user starts it; Chromium
(DevTools protocol, :mod:`puppetphone.bench.chromium`) opens the printed HTTPS link, overrides the
orientation and motion sensors, taps to calibrate, presses the touch area while
pointing at the puppet and turns. The recording is then replayed in-process to check
that the puppet was grabbed and moved, and ``puppetphone replay --verify`` reproduces it.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from puppetphone.bench.chromium import Chromium, find_chromium

pytestmark = pytest.mark.skipif(
    find_chromium() is None, reason="no chromium executable: apt-get install chromium (.ci/run installs it)"
)


def start_play(tmp_path: Path, frames: int, *extra: str, game: str = "sandbox") -> tuple[subprocess.Popen[str], str]:
    """``puppetphone play GAME --source web`` on a free port; the process and its controller link."""
    env = {
        **os.environ,
        "SDL_VIDEODRIVER": "dummy",
        "SDL_AUDIODRIVER": "dummy",
        "XDG_DATA_HOME": str(tmp_path / "data"),
    }
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "puppetphone",
            "play",
            game,
            "--source",
            "web",
            "--web-port",
            "0",
            "--headless",
            "--frames",
            str(frames),
            *extra,
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )
    assert proc.stderr is not None
    end = time.monotonic() + 60
    while time.monotonic() < end:
        line = proc.stderr.readline()
        if not line and proc.poll() is not None:
            break
        m = re.search(r"(https://127\.0\.0\.1:\d+/\?t=\S+)", line)
        if m:
            return proc, m.group(1)
    proc.kill()
    pytest.fail(f"play printed no controller link: {proc.stderr.read()}")


def drive(browser: Chromium, url: str, shot: Path | None = None) -> None:
    """Open the page, allow the sensors, calibrate, grab the puppet and turn with it."""
    browser.enable_sensors()
    browser.open(url)
    browser.wait_for("document.getElementById('state').textContent.startsWith('connected: web:1')")
    browser.click("enable")  # the user gesture iOS needs for its permission prompt
    browser.wait_for("document.getElementById('mode').textContent.includes('orientation 3-DoF')")
    calibrate(browser)
    browser.orientation(0.0, -10.0, 0.0)  # point down at the puppet
    time.sleep(0.2)
    browser.touch("touch", "touchStart")  # grab
    for i in range(90):
        browser.orientation(min(i, 50) * 0.5, -10.0, 0.0)  # turn: the puppet walks sideways
        time.sleep(1 / 60)
    time.sleep(1.0)
    if shot is not None:
        browser.screenshot(shot)
    browser.touch("touch", "touchEnd")  # drop


def calibrate(browser: Chromium) -> None:
    """Answer the page's calibration prompt ("point at the screen"), and see it confirmed."""
    browser.wait_for("!document.getElementById('calib').hidden")
    browser.click("calib-ok")
    browser.wait_for("!document.getElementById('calibrated').hidden")
    time.sleep(0.2)


def replay_in_process(rec: Path) -> tuple[list[int], float, set[str]]:
    """The frames in which the puppet was held, how far it went meanwhile, and the recorded sources."""
    from engine.components import Stick, Transform
    from input.recording import read_recording
    from input.replay import replay_hub
    from puppetphone.games import load_game, make_app

    recording = read_recording(rec)
    game = load_game(recording.header.game)
    hub = replay_hub(recording)
    app = make_app(recording.header.game, recording.header.seed, hub, game.replay_setup(recording.header.setup))
    held: list[int] = []
    start, far, sources = None, 0.0, set()
    for _ in range(len(recording.frames)):
        app.step()
        frame = hub.last_frame
        sources.update(s.source for s in frame.samples)
        stick = app.world.query(Stick)[0][1]
        if stick.grabbed is not None:
            held.append(app.world.frame)
            pos = app.world.get(stick.grabbed, Transform).position
            start = pos.copy() if start is None else start
            far = max(far, float(np.linalg.norm((pos - start)[[0, 2]])))
    return held, far, sources


def test_chromium_grabs_and_moves_the_puppet_and_the_session_replays(tmp_path):
    rec = tmp_path / "web.rec"
    play, url = start_play(tmp_path, 1200, "--record", str(rec))
    try:
        with Chromium() as browser:
            drive(browser, url, tmp_path / "page.png")
        _, err = play.communicate(timeout=120)
    finally:
        if play.poll() is None:
            play.kill()
        play.communicate()
    assert play.returncode == 0, err
    assert (tmp_path / "page.png").stat().st_size > 1000
    held, far, sources = replay_in_process(rec)
    from input.recording import read_recording

    steps = len(read_recording(rec).frames)
    assert sources == {"web:1"}
    assert len(held) > 60, f"the puppet was held for {len(held)} steps only"
    assert far > 0.3, f"the held puppet moved {far:.2f} m only"
    # The replay reproduces the session, seen from the phone and from the orbit camera while held. The
    # phone's replay verifies every step; the orbit camera's (a view, no part of the state) stops at its
    # screenshot, every step up to it verified too: the rest would repeat the phone's check.
    at = held[len(held) // 2]
    shots = {}
    for view, frames in (("phone", []), ("orbit", ["--frames", str(at + 1)])):
        shots[view] = tmp_path / f"{view}.png"
        replay = subprocess.run(
            [
                sys.executable,
                "-m",
                "puppetphone",
                "replay",
                str(rec),
                "--verify",
                "--headless",
                "--view",
                view,
                "--screenshot",
                str(shots[view]),
                "--screenshot-at",
                str(at),
                *frames,
            ],
            capture_output=True,
            text=True,
            timeout=120,
            env={**os.environ, "SDL_VIDEODRIVER": "dummy"},
        )
        assert replay.returncode == 0, replay.stderr
        n = at + 1 if frames else steps
        assert f"replayed {n} frames, all {n} state hashes match" in replay.stdout, replay.stdout
    from PIL import Image

    phone, orbit = (np.asarray(Image.open(shots[v]).convert("L"), dtype=float) for v in ("phone", "orbit"))
    assert np.mean(np.abs(phone - orbit)) > 5.0, "the phone view looks like the orbit view"
