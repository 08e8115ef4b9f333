"""The server thread on loopback (an OS-assigned port): what ``_serve`` hands websockets, seen from both ends.

The keep-alive figures cannot be shown by behaviour without waiting them out (a dead phone is noticed
after ``ping_interval + ping_timeout`` = 15 s), so the test reads them off the server's side of a real
connection instead; the rest is behaviour: the ``Server`` header, the scene pushed after a publish (the
server loop is where ``publish`` wakes the pages), a stop that ends the thread and closes the port.
Broken on purpose by the mutation run (docs/mutation.md, sixth round): each keep-alive figure, the
queue limit, the 64 KiB message limit (one byte over closes the connection), the header and ``_loop``
left unset are each named by an assertion here.
"""

from __future__ import annotations

import json
import socket
import ssl
import time
from collections.abc import Callable
from typing import Any
from urllib.request import urlopen

import pytest
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import connect

from engine.render.scene import RenderScene
from input.web.cert import load_or_create
from input.web.scene_glb import read_scene_glb
from input.web.scene_stream import CameraPose, quantise
from input.web.server import WebSource

CAM = CameraPose((0.0, 1.5, 4.0), (1.0, 0.0, 0.0, 0.0), 60.0)


def _tls() -> ssl.SSLContext:
    ctx = ssl.create_default_context()
    ctx.check_hostname = False
    ctx.verify_mode = ssl.CERT_NONE  # a throwaway certificate of this test
    return ctx


def _until(done: Callable[[], bool], timeout: float = 5.0) -> None:
    """Wait for the server thread to get to ``done`` (polled; at most ``timeout`` seconds)."""
    end = time.monotonic() + timeout
    while not done():
        assert time.monotonic() < end, "timed out"
        time.sleep(0.01)


def test_the_server_keeps_a_phone_alive_pushes_the_scene_and_stops(
    tmp_path: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    src = WebSource(port=0, certificate=load_or_create([], tmp_path / "web"))
    seen: list[Any] = []
    connection: Callable[[Any], Any] = src._connection

    async def watched(ws: Any) -> None:
        seen.append(ws)
        await connection(ws)

    monkeypatch.setattr(src, "_connection", watched)
    src.start()
    try:
        with urlopen(src.url(), context=_tls(), timeout=10) as page:
            assert page.headers["Server"] == "PuppetPhone"
        with connect(f"wss://127.0.0.1:{src.port}/ws?t={src.token}", ssl=_tls(), open_timeout=10) as phone:
            assert json.loads(phone.recv(timeout=5)) == {"hello": "web:1"}
            assert phone.response is not None and phone.response.headers["Server"] == "PuppetPhone"
            (ws,) = seen
            assert (ws.ping_interval, ws.ping_timeout, ws.close_timeout) == (5, 10, 1)
            assert ws.max_queue_high == 32
            scene = RenderScene()
            scene.add_sphere([0.0, 0.3, 0.0], 0.3)
            state = quantise(scene, 3, 0.0, CAM)
            src.publish(state, scene)
            glb = phone.recv(timeout=5)
            assert isinstance(glb, bytes)
            _, got = read_scene_glb(glb)
            assert got.step == 3
            phone.send("x" * (64 * 1024))  # the largest message read (and dropped as malformed)
            phone.send("x" * (64 * 1024 + 1))  # one byte more closes the connection unread
            with pytest.raises(ConnectionClosed):
                phone.recv(timeout=5)
        _until(lambda: src.status().drop_reasons == {"malformed message": 1, "message too big": 1})
    finally:
        src.stop()
    assert src._thread is None and src._sock.fileno() == -1
    with pytest.raises(OSError), socket.create_connection(("127.0.0.1", src.port), timeout=5):
        pass
