"""What the page draws on the ground: blob shadows, the tracks in the snow and footprints, in headless Chromium.

A real :class:`~input.web.server.WebSource` streams a made-up scene (a ball floating a
metre above the snow, a strip of track, two footprints) to the page, seen from straight
above, 6 m up. Where each lands on the screen is worked out here from the sun, the
camera and the page's projection (60° vertical field of view); the page's pixels there
are compared with the same patch of snow mirrored across the picture's middle, where
nothing lies. Break it: a ground shader that ignores the shadow mask (``shadowTint``
left at white) fails the shadow's checks; drawing no decals fails the track's.
"""

from __future__ import annotations

import math
import tempfile
import threading
import time
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from engine.render.scene import GroundMarks, RenderScene
from input.web.cert import load_or_create
from input.web.scene_stream import CameraPose, quantise
from input.web.server import WebSource
from puppetphone.bench.chromium import Chromium, find_chromium

pytestmark = pytest.mark.skipif(
    find_chromium() is None, reason="no chromium executable: apt-get install chromium (.ci/run installs it)"
)

W, H = 390, 844
HEIGHT = 6.0
DOWN = CameraPose((0.0, HEIGHT, 0.0), (math.cos(-math.pi / 4), math.sin(-math.pi / 4), 0.0, 0.0), 60.0)
BALL, RADIUS = np.array([0.0, 1.0, 0.0]), 0.3
TRACK = (0.8, -2.0, 1.6, -1.4)  # x0, z0, x1, z1 of the cleared strip (metres)


def scene() -> RenderScene:
    s = RenderScene()
    s.ground.grid = False
    s.add_sphere(BALL, RADIUS, color=(0.85, 0.45, 0.3))
    amount = np.zeros((80, 80), dtype=np.float32)  # 10 cm cells from (-4, -4)
    x0, z0, x1, z1 = TRACK
    amount[int((z0 + 4) / 0.1) : int((z1 + 4) / 0.1), int((x0 + 4) / 0.1) : int((x1 + 4) / 0.1)] = 1.0
    s.marks = GroundMarks(amount, -4.0, -4.0, 0.1)
    return s


def to_screen(x: float, z: float) -> tuple[int, int]:
    """A point on the ground as a pixel: the camera looks down, screen right is +x, screen up is -z."""
    per_metre = (H / 2) / (HEIGHT * math.tan(math.radians(30.0)))
    return round(W / 2 + x * per_metre), round(H / 2 + z * per_metre)


def patch(img: np.ndarray, x: int, y: int, r: int = 10) -> np.ndarray:
    return img[y - r : y + r, x - r : x + r].reshape(-1, 3).mean(axis=0)


def test_the_ball_casts_its_shadow_along_the_sun_and_the_track_shows_in_the_snow(tmp_path):
    s = scene()
    d = np.asarray(s.sun.direction) / np.linalg.norm(s.sun.direction)
    shadow_x, shadow_z = BALL[0] - d[0] * BALL[1] / d[1], BALL[2] - d[2] * BALL[1] / d[1]
    with tempfile.TemporaryDirectory(prefix="pp-ground-") as folder:
        src = WebSource(port=0, certificate=load_or_create([], Path(folder))).start()
        stop = threading.Event()

        def publish() -> None:
            step = 0
            while not stop.is_set():
                step += 1
                src.publish(quantise(s, step, time.time(), DOWN), s)
                time.sleep(1 / 60)

        th = threading.Thread(target=publish, daemon=True)
        th.start()
        try:
            with Chromium() as browser:
                browser.open(src.url(), W, H)
                browser.wait_for("ppView.drawn > 5", timeout=60)
                browser.evaluate(
                    "document.getElementById('start').hidden = true;"
                    "document.querySelectorAll('header, main, footer').forEach((e) => { e.style.visibility = 'hidden'; })"
                )
                time.sleep(0.5)
                browser.screenshot(tmp_path / "ground.png")
        finally:
            stop.set()
            th.join(2)
            src.stop()
    img = np.asarray(Image.open(tmp_path / "ground.png").convert("RGB"), dtype=np.float64)
    sx, sy = to_screen(shadow_x, shadow_z)
    ball_x, _ = to_screen(BALL[0], BALL[2])
    assert abs(sx - ball_x) > 60, "the test's shadow would lie under the ball itself"
    shade, snow = patch(img, sx, sy), patch(img, W - sx, sy)
    assert snow.min() > 180, f"the mirrored patch is not bright snow: {snow}"
    assert snow.mean() - shade.mean() > 25, f"no shadow where the sun casts the ball: {shade} vs snow {snow}"
    assert shade[2] - shade[0] > snow[2] - snow[0] + 5, "a shadow on snow is blue (the sky's light stays)"
    x0, z0, x1, z1 = TRACK
    tx, ty = to_screen((x0 + x1) / 2, (z0 + z1) / 2)
    track, plain = patch(img, tx, ty, 6), patch(img, W - tx, ty, 6)
    assert plain.mean() - track.mean() > 12, f"no track in the snow: {track} vs snow {plain}"
