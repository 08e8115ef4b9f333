"""``--silent-after``: the stale-peer release is the user's to set, within a sane range, on ``play`` and ``author``.

Broken on purpose to see these fail: ``make_hub`` ignoring ``silent_after`` (the OSC phone is
released after 2 s, the web phone is still held at 0.3 s), and the range check removed
(``--silent-after 0`` and ``1e308`` were accepted and the game ran, exit 0).
"""

from __future__ import annotations

import json
import os
import ssl
import subprocess
import sys
import time
from pathlib import Path

import pytest
from websockets.sync.client import connect

from input.factory import make_hub
from input.osc import ADMIT_AFTER, OscSource
from input.sample import CONNECT, DISCONNECT
from input.web.server import WebSource
from puppetphone.cli import build_parser


def _cli(*args: str, data: Path) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "SDL_VIDEODRIVER": "dummy", "XDG_DATA_HOME": str(data)}
    return subprocess.run(
        [sys.executable, "-m", "puppetphone", *args], env=env, capture_output=True, text=True, check=False, timeout=120
    )


@pytest.mark.parametrize(("command", "value"), [("play", "0"), ("play", "1e308"), ("play", "nan"), ("author", "61")])
def test_an_absurd_silence_is_refused_in_one_line_with_exit_2(tmp_path: Path, command: str, value: str) -> None:
    line = (
        ["play", "sandbox", "--headless", "--frames", "1"] if command == "play" else ["author", "record", "--headless"]
    )
    done = _cli(*line, f"--silent-after={value}", data=tmp_path)
    last = done.stderr.strip().splitlines()[-1]
    assert done.returncode == 2 and "--silent-after" in last and "out of range" in last, done.stderr
    assert "Traceback" not in done.stderr


def _args(*extra: str):  # type: ignore[no-untyped-def]
    return build_parser().parse_args(["play", "sandbox", *extra])


def test_an_osc_phone_keeps_its_puppet_through_the_silence_it_was_given(osc) -> None:  # type: ignore[no-untyped-def]
    message, _ = osc
    args = _args("--source", "osc", "--osc-port", "0", "--silent-after", "5")
    hub = make_hub(args.source, args.osc_host, args.osc_port, args.osc_senders, silent_after=args.silent_after)
    src = hub.sources[0]
    assert isinstance(src, OscSource)
    pose = message("/puppetphone/orientation", 1.0, 0.0, 0.0, 0.0)
    try:
        items = []
        for i in range(ADMIT_AFTER + 2):
            src.handle_datagram(pose, "osc:10.0.0.1", i / 60, 5000)
            items += src.drain()
        assert (CONNECT, "osc:10.0.0.1") in items
        src._expire(0.1 + 3.0)  # silent 3 s: past the default 2 s, within the 5 s asked for
        assert (DISCONNECT, "osc:10.0.0.1") not in src.drain()
        src._expire(0.1 + 5.01)
        assert (DISCONNECT, "osc:10.0.0.1") in src.drain()
    finally:
        src.stop()


def test_a_web_phone_is_released_after_the_silence_it_was_given(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path))  # the certificate is made here, not in the user's folder
    args = _args("--source", "web", "--web-port", "0", "--silent-after", "0.3")
    hub = make_hub(args.source, web_host=args.web_host, web_port=args.web_port, silent_after=args.silent_after)
    src = hub.sources[0]
    assert isinstance(src, WebSource) and src.silent_after == 0.3
    src.start()
    tls = ssl.create_default_context()
    tls.check_hostname, tls.verify_mode = False, ssl.CERT_NONE
    url = f"wss://127.0.0.1:{src.port}/ws?t={src.token}"
    reading = {"seq": 0, "t": 0.0, "kind": "orientation", "o": [0.0, 10.0, 0.0], "touch": False}
    try:
        with connect(url, ssl=tls, open_timeout=10) as frozen:
            assert json.loads(frozen.recv(timeout=5)) == {"hello": "web:1"}
            frozen.send(json.dumps(reading))
            end = time.monotonic() + 5  # a deadline for the test, not a measured rate
            while src.status().drop_reasons.get("silent controller") != 1:
                assert time.monotonic() < end, "the silent phone was never released"
                time.sleep(0.01)
            with connect(url, ssl=tls, open_timeout=10) as fresh:
                assert json.loads(fresh.recv(timeout=5)) == {"hello": "web:1"}
    finally:
        src.stop()
