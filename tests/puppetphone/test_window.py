"""The window a person sees: each scene in a real X window, grabbed from the X server's screen.

A real display (Xvfb) is started for the module; each command runs as a user types it,
with SDL's X11 driver, and the test grabs the **root window of the X server** (ImageMagick's
``import -window root``) while the scene runs — not the engine's off-screen buffer — so a
frame that never reaches the window (a black window) fails here.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
from PIL import Image

from tests.puppetphone.xvfb import SCREEN, needs_x


def _grab(display: str, path: Path) -> np.ndarray:
    subprocess.run(
        ["import", "-display", display, "-window", "root", str(path)], check=True, timeout=30, capture_output=True
    )
    return np.asarray(Image.open(path).convert("RGB"), dtype=np.float64) / 255.0


def _run_and_grab(display: str, args: list[str], tmp_path: Path, lit: float = 0.3) -> np.ndarray:
    """Run ``puppetphone ARGS`` in a window; the X screen once the window shows a scene."""
    env = {**os.environ, "DISPLAY": display, "SDL_VIDEODRIVER": "x11", "XDG_DATA_HOME": str(tmp_path / "data")}
    proc = subprocess.Popen(
        [sys.executable, "-m", "puppetphone", *args],
        env=env,
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        deadline = time.monotonic() + 120
        screen = np.zeros((*SCREEN[::-1], 3))
        while time.monotonic() < deadline and proc.poll() is None:
            time.sleep(1.0)
            screen = _grab(display, tmp_path / "screen.png")
            if screen.mean() > lit:
                time.sleep(1.0)  # let a few more frames draw, then the picture to judge
                screen = _grab(display, tmp_path / "screen.png")
                break
        assert proc.poll() is None, f"the command ended before its window showed a scene:\n{proc.communicate()}"
        return screen
    finally:
        proc.kill()
        proc.communicate(timeout=30)


@needs_x
def test_play_snowman_shows_the_puppet_on_snow_in_the_window(display: str, tmp_path: Path) -> None:
    screen = _run_and_grab(display, ["play", "snowman", "--frames", "100000"], tmp_path)
    r, g, b = screen[..., 0], screen[..., 1], screen[..., 2]
    snow = (r > 0.8) & (g > 0.8) & (b > 0.8)
    assert snow.mean() > 0.4, f"only {snow.mean():.0%} of the screen is snow"
    # The red puppet stands in the middle of the view: warm pixels there, none in the snow.
    h, w = r.shape
    middle = (slice(h // 4, 3 * h // 4), slice(w // 3, 2 * w // 3))
    puppet = (r > g + 0.25) & (r > b + 0.25)
    assert puppet[middle].sum() > 300, "no puppet in the middle of the window"
    assert puppet[middle].mean() > 10 * puppet[: h // 8].mean()


@needs_x
def test_play_tasbada_shows_the_photo_in_the_window(display: str, tmp_path: Path) -> None:
    screen = _run_and_grab(
        display, ["play", "tasbada", "--frames", "100000", "--set", "webcam=off"], tmp_path, lit=0.15
    )
    # The room photo: a varied picture over most of the window, not a flat fill.
    assert screen.std() > 0.1 and (screen.mean(axis=2) > 0.05).mean() > 0.8


@needs_x
def test_author_edit_shows_the_character_and_its_curves(display: str, tmp_path: Path) -> None:
    screen = _run_and_grab(display, ["author", "edit", "walk", "--frames", "100000"], tmp_path, lit=0.15)
    assert (screen.mean(axis=2) > 0.05).mean() > 0.8, "the window is mostly black"
    r, g, b = screen[..., 0], screen[..., 1], screen[..., 2]
    curve = (r > b + 0.3) & (g > b + 0.1)  # the selected item's orange trajectory
    assert curve.sum() > 100, "no MoCurve drawn in the window"
    figure = (np.abs(r - b) < 0.05) & (r > 0.6) & (r < 0.95)  # the grey figure, darker than the ground
    assert figure.sum() > 2000


def test_no_display_refuses_at_once_and_suggests_headless(tmp_path: Path) -> None:
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY", "SDL_VIDEODRIVER")}
    for args in (["play", "snowman"], ["author", "edit", "walk"], ["author", "record"]):
        done = subprocess.run(
            [sys.executable, "-m", "puppetphone", *args],
            env=env,
            cwd=tmp_path,
            capture_output=True,
            text=True,
            timeout=60,
        )
        assert done.returncode == 2, (args, done.stdout, done.stderr)
        assert "no display" in done.stderr and "--headless" in done.stderr
        assert len(done.stderr.strip().splitlines()) == 1


def test_an_invisible_driver_fallback_names_sdls_error_and_tries_x11_by_name(tmp_path: Path) -> None:
    for number in range(700, 800):  # a display nobody serves: SDL falls back to an invisible driver
        if not Path(f"/tmp/.X11-unix/X{number}").exists():
            break
    env = {k: v for k, v in os.environ.items() if k != "SDL_VIDEODRIVER"}
    env.update(DISPLAY=f":{number}", XDG_DATA_HOME=str(tmp_path / "data"))
    done = subprocess.run(
        [sys.executable, "-m", "puppetphone", "play", "snowman", "--frames", "5"],
        env=env,
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 2, done.stderr
    ours = done.stderr.strip().splitlines()[-1]  # SDL's drivers may print their own lines before it
    assert ours.startswith("error: no display (SDL chose its ")
    assert "SDL said: " in ours and "x11 asked for explicitly, 3 times: " in ours and "--headless" in ours


_FIRST_OFFSCREEN = """
import os, pygame
from engine.render import window
real, calls = pygame.display.get_driver, []
def first_offscreen():
    calls.append(1)
    return "offscreen" if len(calls) == 1 else real()
pygame.display.get_driver = first_offscreen
window._open_display()
print(real(), os.environ.get("SDL_VIDEODRIVER", "unset"))
"""


@needs_x
def test_a_passing_offscreen_fallback_is_retried_with_x11_and_opens_the_window(display: str, tmp_path: Path) -> None:
    env = {k: v for k, v in os.environ.items() if k != "SDL_VIDEODRIVER"}
    env["DISPLAY"] = display
    done = subprocess.run(
        [sys.executable, "-c", _FIRST_OFFSCREEN], env=env, cwd=tmp_path, capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.split()[-2:] == ["x11", "unset"]  # x11 by name, the environment left as it was found
