"""Pairing a phone with ``--source web`` from the game window: link, QR code and fingerprint until a page connects.

The QR code is read back with OpenCV's detector from a real headless screenshot of
``puppetphone play sandbox --source web`` and must carry the printed link; the overlay
says "waiting for a phone" (not "[gone]") until one comes, and drops the panel while a
page is connected. ``--view none`` runs a session without any window.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys

import numpy as np
import pytest
from PIL import Image
from websockets.sync.client import connect

from engine.app import App
from engine.render.scene import RenderScene
from games.sandbox import GAME
from input.hub import InputHub
from input.plugin import input_plugin
from input.web.cert import load_or_create
from input.web.server import WebSource
from puppetphone.overlay import draw_overlay, overlay_lines
from tests.input.web.test_server import READING, _tls, _wait

ENV = {**os.environ, "SDL_VIDEODRIVER": "dummy", "SDL_AUDIODRIVER": "dummy"}


def test_the_window_shows_a_qr_code_that_carries_the_printed_link(tmp_path):
    cv2 = pytest.importorskip("cv2")
    shot = tmp_path / "pairing.png"
    res = subprocess.run(
        [
            sys.executable,
            "-m",
            "puppetphone",
            "play",
            "sandbox",
            "--source",
            "web",
            "--web-port",
            "0",
            "--headless",
            "--frames",
            "2",
            "--size",
            "960x540",
            "--screenshot",
            str(shot),
        ],
        capture_output=True,
        text=True,
        timeout=120,
        env={**ENV, "XDG_DATA_HOME": str(tmp_path)},
    )
    assert res.returncode == 0, res.stderr
    link = re.search(r"(https://127\.0\.0\.1:\d+/\?t=\S+)", res.stderr).group(1)
    img = np.asarray(Image.open(shot).convert("RGB"))
    text, points, _ = cv2.QRCodeDetector().detectAndDecode(img)
    assert text == link, f"the window's QR code reads {text!r}"
    corners = points.reshape(-1, 2)
    assert corners[:, 0].min() > img.shape[1] / 2, "the QR code should stand at the right, clear of the text lines"


def test_the_overlay_waits_for_a_phone_and_hides_the_panel_while_one_is_connected(tmp_path):
    src = WebSource(port=0, certificate=load_or_create([], tmp_path / "web")).start()
    hub = InputHub([src])
    try:
        app = App(seed=0)
        app.add_plugin(input_plugin(hub))
        app.add_plugin(GAME.install)
        app.step()
        lines = overlay_lines(app.world, GAME, hub, 60.0, False)
        assert any(src.url("127.0.0.1") in line for line in lines)
        assert any(src.certificate.fingerprint in line for line in lines)
        assert any("[waiting for a phone]" in line for line in lines) and not any("[gone]" in line for line in lines)
        scene = RenderScene()
        draw_overlay(scene, app.world, GAME, hub, 60.0, False, size=(960, 540))
        assert len(scene.overlays) == 1
        with connect(f"wss://127.0.0.1:{src.port}/ws?t={src.token}", ssl=_tls(), open_timeout=10) as ws:
            ws.recv(timeout=5)
            ws.send(json.dumps(READING))
            _wait(lambda: src.viewers == 1)
            app.step()
            lines = overlay_lines(app.world, GAME, hub, 60.0, False)
            assert not any(src.token in line for line in lines), "the link stays up while a phone is connected"
            scene = RenderScene()
            draw_overlay(scene, app.world, GAME, hub, 60.0, False, size=(960, 540))
            assert not scene.overlays
        _wait(lambda: src.viewers == 0)
        app.step()
        lines = overlay_lines(app.world, GAME, hub, 60.0, False)
        assert any("[gone]" in line for line in lines), "a phone that was there and left is gone"
        assert any(src.token in line for line in lines), "the link comes back for the next phone"
    finally:
        hub.close()


def test_view_none_plays_without_a_window_or_a_display(tmp_path, capsys, monkeypatch):
    from puppetphone.cli import main

    for name in ("DISPLAY", "WAYLAND_DISPLAY"):
        monkeypatch.delenv(name, raising=False)
    assert main(["play", "sandbox", "--view", "none", "--frames", "30"]) == 0
    assert "ran 30 steps" in capsys.readouterr().out
    assert main(["play", "sandbox", "--view", "none", "--frames", "3", "--screenshot", str(tmp_path / "x.png")]) == 2
    assert "--view none draws nothing" in capsys.readouterr().err
