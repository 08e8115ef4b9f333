"""Every sample that arrives within one step takes effect, from every kind of device.

At 60 steps a second a 125 Hz mouse, a 100 Hz phone or a 250 Hz gamepad delivers two or
more readings per step. The stick stage used to read only the newest: wheel notches,
flicks and taps inside a step were lost. Each device here goes through its own real
path (pygame events into the mouse source, OSC datagrams into the OSC source, a serial
read loop over a scripted port, a HID read loop over scripted reports, the web page's
messages through its protocol), several readings land in one step, and the test checks
that all of them counted.
"""

from __future__ import annotations

import json
import struct

import numpy as np
import pygame
import pytest

from engine.components import Stick, Transform
from engine.statemachine import Brain
from input.hid import HidSource
from input.hub import InputHub
from input.motionstick import StickState
from input.mouse import MouseSource
from input.osc import OscSource
from input.sample import TOUCH_DOWN, TOUCH_UP, PoseSample
from input.serial_parse import SerialStreamParser
from input.serial_source import SerialSource
from input.source import PoseSource
from input.web.protocol import ControllerMessage, PageClock, parse_message, to_sample_fields
from puppetphone.games import load_game, make_app

SIZE = (1280, 720)


def _sandbox(source: PoseSource):  # type: ignore[no-untyped-def]
    app = make_app("sandbox", 0, InputHub([source]), {"scene": "empty", "puppets": 1})
    puppet = next(e for e, _ in app.world.query(Brain))
    return app, puppet


def _stick(app):  # type: ignore[no-untyped-def]
    return next((s, st) for _, s, st in app.world.query(Stick, StickState))


# -- the mouse ------------------------------------------------------------------------------


def _mouse_grab():  # type: ignore[no-untyped-def]
    mouse = MouseSource()
    app, puppet = _sandbox(mouse)
    camera = load_game("sandbox").camera()
    anchor = app.world.get(puppet, Transform).position + np.array([0.0, 0.95, 0.0])
    px = camera.project(anchor[None], *SIZE)[0]
    send = lambda kind, t, **a: mouse.handle_event(pygame.event.Event(kind, **a), camera, SIZE, now=t)  # noqa: E731
    send(pygame.MOUSEMOTION, 0.0, pos=tuple(px), rel=(0, 0), buttons=(0, 0, 0))
    app.step()
    send(pygame.MOUSEBUTTONDOWN, 0.02, pos=tuple(px), button=1)
    app.step()
    stick, st = _stick(app)
    assert stick.grabbed == puppet
    return app, send, st, tuple(px)


def test_mouse_wheel_notches_within_a_step_all_count():
    app, send, st, px = _mouse_grab()
    depth = st.depth
    for k in range(3):  # three notches down and three up, all before the next step
        send(pygame.MOUSEWHEEL, 0.03 + 0.001 * k, x=0, y=-1)
    for k in range(3):
        send(pygame.MOUSEWHEEL, 0.04 + 0.001 * k, x=0, y=1)
    app.step()
    assert st.depth == pytest.approx(depth)  # the last notch alone would leave it 0.1 m off
    for k in range(19):  # more notches than the hub keeps samples of a step: none is lost
        send(pygame.MOUSEWHEEL, 0.05 + 0.001 * k, x=0, y=-1)
    app.step()
    assert st.depth == pytest.approx(depth + 1.9)


def test_a_mouse_flick_inside_a_step_is_not_lost_behind_later_motion():
    app, send, st, (x, y) = _mouse_grab()
    stick, _ = _stick(app)
    times = np.linspace(0.03, 0.045, 6)
    for k, t in enumerate(times[:3]):  # up 120 px quickly ...
        send(pygame.MOUSEMOTION, t, pos=(x, y - 40.0 * (k + 1)), rel=(0, -40), buttons=(1, 0, 0))
    for k, t in enumerate(times[3:]):  # ... and back down, all within one step
        send(pygame.MOUSEMOTION, t, pos=(x, y - 120.0 + 40.0 * (k + 1)), rel=(0, 40), buttons=(1, 0, 0))
    app.step()
    assert stick.flick


def test_a_slow_upward_mouse_drag_handled_in_bursts_is_not_a_flick():
    """30 px/s, events queued during a frame and handled a millisecond apart: event time decides."""
    mouse = MouseSource()
    flicks = 0
    camera = load_game("sandbox").camera()
    mouse.handle_event(pygame.event.Event(pygame.MOUSEBUTTONDOWN, pos=(640, 500), button=1), camera, SIZE, now=0.0)
    for k in range(1, 121):  # 2 s at 60 Hz, one pixel every two frames
        event = pygame.event.Event(pygame.MOUSEMOTION, pos=(640, 500 - k // 2), rel=(0, -1), buttons=(1, 0, 0))
        mouse.handle_event(event, camera, SIZE, now=k / 60.0)
        flicks += sum(s.flick for s in mouse.drain() if isinstance(s, PoseSample))
    assert flicks == 0


# -- devices in "device" mode: taps inside a step ---------------------------------------------


def _tap_counted(app) -> None:  # type: ignore[no-untyped-def]
    """A tap (down and up) inside one step: both edges reached the stick (the first tap calibrates)."""
    from input.sample import InputFrame

    app.step()
    frame = app.world.resource(InputFrame)
    kinds = [k for k, _ in frame.events]
    assert TOUCH_DOWN in kinds and TOUCH_UP in kinds
    stick, st = _stick(app)
    assert st.calibrated and not stick.touching
    assert len(frame.samples) >= 3


def test_osc_datagrams_within_a_step_all_reach_the_stick(osc):
    message, _ = osc
    source = OscSource(port=0, admit_after=1)
    try:
        app, _ = _sandbox(source)
        for k, touch in enumerate((None, 1, None, 0)):
            now = 0.001 * k
            source.handle_datagram(message("/puppetphone/orientation", 1.0, 0.0, 0.0, 0.0), "127.0.0.1:5000", now)
            if touch is not None:
                source.handle_datagram(message("/puppetphone/touch", touch), "127.0.0.1:5000", now)
        _tap_counted(app)
    finally:
        source.stop()


class _Port:
    """A serial port whose reads return scripted chunks, then stop the read loop."""

    def __init__(self, source: SerialSource, chunks: list[bytes]) -> None:
        self.source, self.chunks = source, list(chunks)

    @property
    def in_waiting(self) -> int:
        return len(self.chunks[0]) if self.chunks else 0

    def read(self, n: int) -> bytes:
        if not self.chunks:
            self.source.stopping.set()
            return b""
        return self.chunks.pop(0)


def test_serial_lines_within_a_step_all_reach_the_stick():
    source = SerialSource("/dev/null-scripted")
    app, _ = _sandbox(source)
    source.parser = SerialStreamParser()
    lines = b"1,0,0,0,0,0,0,0\n1,0,0,0,0,0,0,1\n1,0,0,0,0,0,0,1\n1,0,0,0,0,0,0,0\n"
    source._read_loop(_Port(source, [lines]))  # one read delivers the whole burst
    _tap_counted(app)


def _ds4(cross: bool, ts: int) -> bytes:
    r = bytearray(64)
    r[0] = 0x01
    r[5] = 0x08 | (0x20 if cross else 0)
    struct.pack_into("<H", r, 10, ts)
    struct.pack_into("<3h", r, 19, 0, 8192, 0)  # gravity along the pad's Y
    return bytes(r)


class _Pad:
    """A DualShock 4 whose reads return scripted reports, then stop the read loop."""

    def __init__(self, source: HidSource, reports: list[bytes]) -> None:
        self.source, self.reports = source, list(reports)

    def get_feature_report(self, rid: int, n: int) -> list[int]:
        raise OSError("no calibration report in this script")

    def read(self, n: int, timeout: int) -> list[int]:
        if not self.reports:
            self.source.stopping.set()
            return []
        return list(self.reports.pop(0))


def test_hid_reports_within_a_step_all_reach_the_stick():
    source = HidSource()
    app, _ = _sandbox(source)
    source.kind, source.source_id = "ds4", "hid:054c:05c4"
    reports = [_ds4(c, 188 * k) for k, c in enumerate((False, True, True, False))]  # 4 ms apart
    source._read_loop(_Pad(source, reports))
    _tap_counted(app)


class _Page(PoseSource):
    threaded = False

    def __init__(self) -> None:
        super().__init__("web")
        self.clock = PageClock()

    def send(self, arrival: float, **fields: object) -> None:
        msg = parse_message(json.dumps({"seq": 0, "kind": "orientation", "o": [0, 90, 0], **fields}))
        assert isinstance(msg, ControllerMessage)
        self.push(PoseSample(**to_sample_fields(msg, "web:1", self.clock.stamp(msg.t, arrival))))


def test_web_messages_within_a_step_all_reach_the_stick_and_keep_their_event_times():
    page = _Page()
    app, _ = _sandbox(page)
    page.send(4.0, t=999_000.0, touch=False)  # a reading that came straight through sets the clock
    app.step()
    # Four readings 10 ms apart on the phone, arriving together after a Wi-Fi stall.
    for k, touch in enumerate((False, True, True, False)):
        page.send(5.05, t=1_000_000.0 + 10.0 * k, touch=touch)
    _tap_counted(app)
    from input.sample import InputFrame

    times = [s.time for s in app.world.resource(InputFrame).samples]
    assert np.allclose(np.diff(times), 0.01)  # the page's spacing, not the burst's


def test_a_page_clock_is_never_stamped_after_its_arrival():
    clock = PageClock()
    assert clock.stamp(1000.0, 50.0) == pytest.approx(50.0)
    assert clock.stamp(1020.0, 50.2) == pytest.approx(50.02)  # a late arrival keeps its event time
    assert clock.stamp(1030.0, 50.01) == pytest.approx(50.01)  # a quicker one moves the offset
    assert clock.stamp(500_000.0, 51.0) == pytest.approx(51.0)  # a clock jump restarts the estimate
