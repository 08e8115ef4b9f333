"""The window target on a software rasteriser: frames go straight into the window's framebuffer,
and a frame asked to be kept can still be read back.

A real X server (Xvfb) runs a small program that opens a :class:`~engine.render.window.WindowTarget`,
draws red frames through ``begin``/``end`` and waits; the test grabs the X server's screen
(ImageMagick's ``import``), so a frame that never reaches the window fails here.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
from PIL import Image

from tests.puppetphone.xvfb import display, needs_x  # noqa: F401 - display: a fixture, found by name

_PROGRAM = """
import json, sys
from engine.render.window import WindowTarget
t = WindowTarget(320, 240, vsync=False)
software = "llvmpipe" in t.ctx.info["GL_RENDERER"].lower()
def frame(colour):
    fb = t.begin()
    fb.clear(*colour, 1.0, depth=1.0)
    t.end()
for _ in range(3):
    frame((1.0, 0.0, 0.0))
t.ctx.finish()
try:
    t.read_pixels()
    refused = False
except RuntimeError:
    refused = True
print(json.dumps({"straight": t.straight, "software": software, "refused": refused}), flush=True)
sys.stdin.readline()  # the test grabs the screen now
t.keep_next_frame()
frame((0.0, 1.0, 0.0))
kept = t.read_pixels()
frame((0.0, 0.0, 1.0))
print(json.dumps({"kept": kept[120, 160].tolist()}), flush=True)
t.close()
"""


@needs_x
def test_frames_reach_the_window_straight_and_a_kept_frame_reads_back(display: str, tmp_path: Path) -> None:  # noqa: F811
    """Broken once by copying the off-screen buffer to the window in every ``end()`` (the straight
    frame's red is overwritten by the empty buffer): the grab finds no red; once by ignoring
    ``keep_next_frame`` (drawn straight): reading the frame back is refused and the test fails."""
    env = {**os.environ, "DISPLAY": display, "SDL_VIDEODRIVER": "x11", "PYGAME_HIDE_SUPPORT_PROMPT": "1"}
    env["PYTHONPATH"] = str(Path(__file__).resolve().parents[3])  # the checkout under test
    proc = subprocess.Popen(
        [sys.executable, "-c", _PROGRAM],
        env=env,
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert proc.stdout is not None and proc.stdin is not None
        first = json.loads(proc.stdout.readline() or "null") or {}
        assert first, proc.stderr.read() if proc.stderr else "no output"
        if first["software"]:
            assert first["straight"] and first["refused"]
        shot = tmp_path / "screen.png"
        subprocess.run(["import", "-display", display, "-window", "root", str(shot)], check=True, timeout=30)
        screen = np.asarray(Image.open(shot).convert("RGB"), dtype=np.int32)
        red = (screen[..., 0] > 200) & (screen[..., 1] < 50) & (screen[..., 2] < 50)
        assert red.sum() >= 0.9 * 320 * 240, f"{red.sum()} red pixels on the X screen"
        proc.stdin.write("\n")
        proc.stdin.flush()
        second = json.loads(proc.stdout.readline() or "null") or {}
        assert second.get("kept") == [0, 255, 0], second
    finally:
        proc.kill()
        proc.communicate(timeout=30)
