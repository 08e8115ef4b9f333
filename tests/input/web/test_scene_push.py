"""The server's scene push on loopback: the GLB first, then frames, never more than the page has acknowledged.

A page that stops acknowledging (a slow phone) gets at most ``FRAMES_IN_FLIGHT``
frames and then nothing, however many steps are published meanwhile; when it
acknowledges again the next frame is the newest step, not the backlog.
"""

from __future__ import annotations

import json
import time

import numpy as np
import pytest
from websockets.sync.client import ClientConnection, connect

from engine.render.scene import RenderScene
from input.web.cert import load_or_create
from input.web.scene_glb import read_scene_glb
from input.web.scene_stream import CameraPose, SceneState, decode_frame, quantise
from input.web.server import FRAMES_IN_FLIGHT, WebSource
from tests.input.web.test_server import _tls, _wait

CAM = CameraPose((0.0, 1.5, 4.0), (1.0, 0.0, 0.0, 0.0), 60.0)


@pytest.fixture
def source(tmp_path):
    src = WebSource(port=0, certificate=load_or_create([], tmp_path / "web"), max_rate=1000.0).start()
    yield src
    src.stop()


def publish(src: WebSource, step: int) -> None:
    scene = RenderScene()
    scene.add_capsule([0.0, 0.5, 0.01 * step], [0.0, 1.0, 0.01 * step], 0.05)
    src.publish(quantise(scene, step, time.time(), CAM), scene)


def test_a_page_that_stops_acknowledging_gets_no_backlog_and_then_the_newest_step(source):
    with connect(f"wss://127.0.0.1:{source.port}/ws?t={source.token}", ssl=_tls(), open_timeout=10) as ws:
        assert json.loads(ws.recv(timeout=5)) == {"hello": "web:1"}
        _wait(lambda: source.viewers == 1)
        for step in range(1, 61):  # a second of steps, never acknowledged
            publish(source, step)
            time.sleep(0.002)
        got = []
        while True:
            try:
                got.append(ws.recv(timeout=0.5))
            except TimeoutError:
                break
        assert len(got) == FRAMES_IN_FLIGHT, f"{len(got)} messages to a page that acknowledged none"
        _, state = read_scene_glb(got[0])
        state = decode_frame(state, got[1])
        for step in range(61, 121):
            publish(source, step)
        time.sleep(0.05)
        ws.send(json.dumps({"ack": state.step}))
        newest = decode_frame(state, ws.recv(timeout=5))
        assert newest.step == 120, "after the ack the page should get the newest step, not the next one in a queue"
        assert newest.rows["capsules"][0, 2] == 1200  # 0.01 m × 120 in millimetres
        _wait(lambda: source.frames_sent == FRAMES_IN_FLIGHT + 1)


def test_an_acknowledging_page_gets_frames_delta_coded_against_what_it_has(source):
    with connect(f"wss://127.0.0.1:{source.port}/ws?t={source.token}", ssl=_tls(), open_timeout=10) as ws:
        ws.recv(timeout=5)
        _wait(lambda: source.viewers == 1)
        publish(source, 1)
        _, state = read_scene_glb(ws.recv(timeout=5))
        ws.send(json.dumps({"ack": state.step}))
        steps, sizes = [], []
        for step in range(2, 12):
            publish(source, step)
            data = ws.recv(timeout=5)
            state = decode_frame(state, data)
            ws.send(json.dumps({"ack": state.step}))
            steps.append(state.step)
            sizes.append(len(data))
        assert steps == list(range(2, 12))
        assert np.array_equal(state.rows["capsules"][0, [2, 5]], [110, 110])
        assert max(sizes) < 80, f"one moved capsule should cost a few bytes over the header, got {max(sizes)}"


@pytest.mark.parametrize("bad", ['{"ack": -1}', '{"ack": 1.5}', '{"ack": true}', '{"ack": 1, "seq": 2}'])
def test_an_ack_is_a_step_number_or_it_is_dropped_as_malformed(bad):
    from input.web.protocol import Ack, WebMessageError, parse_message

    assert parse_message('{"ack": 42}') == Ack(42)
    with pytest.raises(WebMessageError):
        parse_message(bad)


def _binary(message: str | bytes) -> bytes:
    assert isinstance(message, bytes), "scene frames are binary messages"
    return message


def _watching_from_step_1(ws: ClientConnection, source: WebSource) -> SceneState:
    """Past the page's hello: step 1 published, its whole scene received and acknowledged."""
    ws.recv(timeout=5)
    _wait(lambda: source.viewers == 1)
    publish(source, 1)
    _, state = read_scene_glb(_binary(ws.recv(timeout=5)))
    ws.send(json.dumps({"ack": state.step}))
    return state


def test_a_frame_right_after_a_pong_is_not_held_for_the_pages_delayed_ack(source: WebSource) -> None:
    """The page pings once a second; the frame published just after the pong must go at once.

    With Nagle's algorithm on (the listening socket made without ``IPPROTO_TCP``, so asyncio
    does not set ``TCP_NODELAY``), the frame waits until the client's kernel acknowledges the
    pong, which it delays by 40 ms: every wait is then 39-48 ms (tried); without it 1-16 ms.
    """
    with connect(f"wss://127.0.0.1:{source.port}/ws?t={source.token}", ssl=_tls(), open_timeout=10) as ws:
        state = _watching_from_step_1(ws, source)
        waits = []
        for step in range(2, 12):
            ws.send(json.dumps({"ping": 1.0}))
            assert "pong" in json.loads(ws.recv(timeout=5))
            start = time.perf_counter()
            publish(source, step)
            state = decode_frame(state, _binary(ws.recv(timeout=5)))
            waits.append(1000.0 * (time.perf_counter() - start))
            ws.send(json.dumps({"ack": state.step}))
        assert state.step == 11
        assert float(np.median(waits)) < 25.0, f"frames after a pong waited {sorted(round(w, 1) for w in waits)} ms"


def test_a_page_that_keeps_up_gets_frames_coded_on_the_publishing_thread(
    source: WebSource, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The frame from the previous step is coded once, at publication, so the server thread only writes it.

    Coding it in the server thread (as before) fails the thread check: every frame there.
    """
    import threading

    import input.web.server as server

    coded_on: list[int] = []
    real = server.encode_frame

    def spy(base: SceneState, state: SceneState) -> bytes:
        coded_on.append(threading.get_ident())
        return real(base, state)

    monkeypatch.setattr(server, "encode_frame", spy)
    with connect(f"wss://127.0.0.1:{source.port}/ws?t={source.token}", ssl=_tls(), open_timeout=10) as ws:
        state = _watching_from_step_1(ws, source)
        for step in range(2, 8):
            publish(source, step)
            state = decode_frame(state, _binary(ws.recv(timeout=5)))
            ws.send(json.dumps({"ack": state.step}))
            assert state.step == step
        assert state.rows["capsules"][0, 2] == 70  # 0.01 m × 7 in millimetres
    here = threading.get_ident()
    assert coded_on and all(t == here for t in coded_on), f"{sum(t != here for t in coded_on)} frames coded elsewhere"
