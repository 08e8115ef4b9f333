"""``author flow`` in a real X window: the scene shows at once while its SEcurves are found (no black window)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
from PIL import Image

from tests.puppetphone.xvfb import SCREEN, needs_x


@needs_x
def test_the_flow_editor_shows_the_scene_while_its_securves_are_found(display: str, tmp_path: Path) -> None:
    env = {**os.environ, "DISPLAY": display, "SDL_VIDEODRIVER": "x11", "XDG_DATA_HOME": str(tmp_path / "data")}
    proc = subprocess.Popen(
        [sys.executable, "-m", "puppetphone", "author", "flow", "--frames", "100000"],
        env=env,
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )  # fmt: skip  (its own group: the search's process ends with it)
    try:
        deadline = time.monotonic() + 60
        screen = np.zeros((SCREEN[1], SCREEN[0], 3))
        while time.monotonic() < deadline and proc.poll() is None and screen.mean() < 0.3:
            time.sleep(0.5)
            subprocess.run(["import", "-display", display, "-window", "root", str(tmp_path / "s.png")], check=True,
                           timeout=30, capture_output=True)  # fmt: skip
            screen = np.asarray(Image.open(tmp_path / "s.png").convert("RGB"), dtype=np.float64) / 255.0
        assert proc.poll() is None, proc.communicate()
        r, g, b = screen[..., 0], screen[..., 1], screen[..., 2]
        assert (screen.mean(axis=2) > 0.05).mean() > 0.8, "the window is black"
        trees = (g > r + 0.08) & (g > b - 0.05) & (g < 0.8)
        assert trees.sum() > 2000, "no trees drawn"
        securves = (b > 0.8) & (r < 0.35) & (g < 0.6)
        assert securves.sum() < 50, "the SEcurves were already drawn: this frame was not during their search"
    finally:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.communicate(timeout=30)
