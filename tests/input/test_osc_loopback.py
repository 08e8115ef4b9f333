"""Real peers on loopback: python-osc in another process, liblo's oscsend, and a flood."""

from __future__ import annotations

import shutil
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

from engine.components import Stick
from input.hub import InputHub
from input.osc import (
    ADMIT_AFTER,
    CANDIDATE_BUDGET,
    MAX_BUNDLE_DEPTH,
    MAX_CANDIDATES,
    MAX_DATAGRAM,
    MAX_MESSAGES,
    STEP_BUDGET,
    OscSource,
    bundle_shape,
)
from input.sample import CONNECT, TOUCH_DOWN

ZIG_SENDER = textwrap.dedent("""
    import math, socket, sys, time
    from pythonosc.osc_bundle_builder import OscBundleBuilder, IMMEDIATELY
    from pythonosc.osc_message_builder import OscMessageBuilder
    port, n = int(sys.argv[1]), int(sys.argv[2])
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    def msg(addr, *args):
        b = OscMessageBuilder(addr)
        for a in args: b.add_arg(a)
        return b.build()
    for i in range(n):
        a = -0.9 + 0.6 * i / n                       # pitch the phone from pointing down towards level
        q = (math.sin(a / 2), 0.0, 0.0, math.cos(a / 2))  # x,y,z,w about the device X axis
        bb = OscBundleBuilder(IMMEDIATELY)
        bb.add_content(msg("/ZIGSIM/abc123/quaternion", *q))
        if 5 <= i:
            bb.add_content(msg("/ZIGSIM/abc123/touch01", 0.0)); bb.add_content(msg("/ZIGSIM/abc123/touch02", 0.0))
        sock.sendto(bb.build().dgram, ("127.0.0.1", port))
        if i % 3 == 0:
            sock.sendto(b"\\x00garbage\\xff" * 3, ("127.0.0.1", port))
        time.sleep(1 / 120)
""")


def _wait_for(pred, timeout=5.0):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if pred():
            return True
        time.sleep(0.01)
    return False


def test_zigsim_bundles_from_another_process_move_the_stick(make_app):
    src = OscSource(host="127.0.0.1", port=0)
    hub = InputHub([src]).start()
    app = make_app(hub)
    try:
        proc = subprocess.Popen([sys.executable, "-c", ZIG_SENDER, str(src.port), "60"])
        tips, events = [], []
        end = time.monotonic() + 10
        while proc.poll() is None and time.monotonic() < end:
            time.sleep(1 / 60)
            app.step()
            events += app.world.resource(type(hub.last_frame)).events
            tips.append(app.world.query(Stick)[0][1].tip.copy())
        proc.wait(5)
        time.sleep(0.05)
        app.step()
        stick = app.world.query(Stick)[0][1]
    finally:
        hub.close()
    kinds = [k for k, _ in events]
    assert kinds[0] == CONNECT and TOUCH_DOWN in kinds
    assert stick.source == "osc:127.0.0.1" and stick.connected and stick.touching
    st = src.status()
    assert st.packets >= 50 and st.drop_reasons.get("malformed packet", 0) >= 15
    # Calibrated by the first tap: the stick then points forward (+Z) and pitching up lifts the tip.
    assert stick.direction[2] > 0.5 and abs(stick.direction[0]) < 1e-6
    assert tips[-1][1] > tips[len(tips) // 2][1]


@pytest.mark.skipif(shutil.which("oscsend") is None, reason="liblo-tools' oscsend is not installed")
def test_oscsend_messages_for_each_profile():
    src = OscSource(host="127.0.0.1", port=0, admit_after=1)  # every message counts here, the first too
    hub = InputHub([src]).start()
    try:
        sends = [
            ["/rotationvector", "fffff", "0", "0", "0", "1", "0.1"],
            ["/touch1", "ff", "0.5", "0.5"],
            ["/accxyz", "fff", "0", "0", "-1"],
            ["/gyrosc/quat", "ffff", "1", "0", "0", "0"],
            ["/puppetphone/pose", "fffffff", "0.1", "0.2", "0.3", "1", "0", "0", "0"],
            ["/puppetphone/orientation", "ffff", "nan", "0", "0", "1"],
            ["/ZIGSIM/u/quaternion", "ssss", "a", "b", "c", "d"],
        ]
        for args in sends:
            subprocess.run(["oscsend", "127.0.0.1", str(src.port), *args], check=True, timeout=5)
        assert _wait_for(lambda: src.status().packets >= 5 and src.status().dropped >= 2)
        frame = hub.drain(0)
    finally:
        hub.close()
    assert len(frame.samples) == 5
    assert frame.samples[1].touch is True
    assert np.allclose(frame.samples[-1].position, [0.1, 0.2, 0.3])
    assert src.status().drop_reasons == {"non-finite value": 1, "wrong type": 1}


def test_flood_of_ten_thousand_packets_keeps_the_step_cheap(make_app, osc):
    message, _ = osc
    src = OscSource(host="127.0.0.1", port=0, max_rate=1e9)
    hub = InputHub([src]).start()
    app = make_app(hub)
    good = message("/puppetphone/orientation", 1.0, 0.0, 0.0, 0.0)
    bad = [b"\xff" * 40, good[:-3], message("/puppetphone/orientation", float("nan"), 0.0, 0.0, 1.0)]
    import socket

    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        worst = 0
        for i in range(10_000):
            sock.sendto(good if i % 4 == 0 else bad[i % 3], ("127.0.0.1", src.port))
            if i % 500 == 499:  # a step now and then while the flood goes on
                app.step()
                worst = max(worst, len(app.world.resource(type(hub.last_frame)).samples))
        seen = -1
        while seen != (seen := src.status().packets + src.status().dropped):
            time.sleep(0.1)  # until the receiver has worked through what the kernel kept
        app.step()
    finally:
        sock.close()
        hub.close()
    st = src.status()
    assert worst <= hub.max_samples
    # What the kernel's buffer kept is either a sample or a counted drop with its reason; past
    # the step's decoding budget, datagrams are dropped undecoded.
    assert st.packets > 20 and st.dropped > 2 * 100
    assert {"malformed packet", "non-finite value", "over budget"} <= set(st.drop_reasons)
    assert app.world.query(Stick)[0][1].connected


def test_locked_to_first_sender_and_rate_limited(osc):
    message, _ = osc
    src = OscSource(host="127.0.0.1", port=0, max_rate=10)
    try:
        pkt = message("/puppetphone/orientation", 1.0, 0.0, 0.0, 0.0)
        for i in range(30):
            src.handle_datagram(pkt, "osc:10.0.0.1", now=100.0)
            if i % 2:
                src.drain()  # steps go by: the decoding budget is not what is tested here
        src.handle_datagram(pkt, "osc:10.0.0.2", now=100.0)
        st = src.status()
        assert st.drop_reasons == {"rate limit": 20, "sender pending": 2, "other sender": 1}
        assert st.locked_out == ["osc:10.0.0.2"]
        src.handle_datagram(message("/puppetphone/touch", 1), "osc:10.0.0.1", now=101.0)  # tokens refilled
        assert src.drain()[-1].touch is True
    finally:
        src.stop()


def test_garbage_or_a_stray_datagram_cannot_claim_the_slot(osc):
    message, _ = osc
    src = OscSource(host="127.0.0.1", port=0)
    pose = message("/puppetphone/orientation", 1.0, 0.0, 0.0, 0.0)
    try:
        src.handle_datagram(b"\x00garbage", "osc:10.0.0.66", now=1.0)  # first on the wire: used to lock everyone out
        src.handle_datagram(pose, "osc:10.0.0.77", now=1.0)  # one valid datagram is not a pose stream either
        items = []
        for i in range(5):  # a phone at 60 Hz, one datagram a step
            src.handle_datagram(pose, "osc:10.0.0.5", now=1.0 + i / 60)
            items += src.drain()
        for sender in ("osc:10.0.0.66", "osc:10.0.0.77"):
            for _ in range(5):
                src.handle_datagram(pose, sender, now=1.1)
        items += src.drain()
        assert items[0] == (CONNECT, "osc:10.0.0.5")
        assert {i.source for i in items[1:]} == {"osc:10.0.0.5"} and len(items) == 1 + 5 - (ADMIT_AFTER - 1)
        st = src.status()
        assert st.locked_out == ["osc:10.0.0.66", "osc:10.0.0.77"] and st.drop_reasons["other sender"] == 10
    finally:
        src.stop()


def test_candidates_are_bounded_and_forgotten_when_quiet(osc):
    message, _ = osc
    src = OscSource(host="127.0.0.1", port=0, timeout=2.0)
    try:
        for i in range(MAX_CANDIDATES + 5):
            src.handle_datagram(b"junk", f"osc:10.1.0.{i}", now=1.0)
        assert src.status().drop_reasons["too many senders"] == 5
        src._expire(10.0)  # every candidate went quiet
        pose = message("/puppetphone/orientation", 1.0, 0.0, 0.0, 0.0)
        items = []
        for i in range(ADMIT_AFTER):  # one datagram a step
            src.handle_datagram(pose, "osc:10.2.0.1", now=10.0 + i / 60)
            items += src.drain()
        assert items[0] == (CONNECT, "osc:10.2.0.1")
    finally:
        src.stop()


def test_no_sender_slots_is_refused():
    with pytest.raises(ValueError, match="OSC senders must be at least 1"):
        OscSource(host="127.0.0.1", port=0, max_senders=0)


def test_bind_error_is_clear():
    a = OscSource(host="127.0.0.1", port=0)
    try:
        with pytest.raises(OSError, match="cannot listen for OSC on 127.0.0.1"):
            OscSource(host="127.0.0.1", port=a.port)
    finally:
        a.stop()


def test_bundles_are_measured_without_parsing(osc):
    message, bundle = osc
    pose = ("/puppetphone/orientation", 1.0, 0.0, 0.0, 0.0)
    assert bundle_shape(message(*pose)) == (1, "")
    assert bundle_shape(bundle(pose, pose, pose)) == (3, "")
    assert bundle_shape(bundle(*[pose] * (MAX_MESSAGES + 1)))[1] == "bundle too large"
    nested = bundle(pose)
    for _ in range(MAX_BUNDLE_DEPTH):
        nested = b"#bundle\x00" + bytes(8) + len(nested).to_bytes(4, "big") + nested
    assert bundle_shape(nested)[1] == "bundle too deep"
    assert bundle_shape(b"#bundle\x00" + bytes(8) + (10**9).to_bytes(4, "big")) == (0, "")  # lying sizes: python-osc's


def test_decoding_is_budgeted_per_sender_and_step(osc):
    message, bundle = osc
    src = OscSource(host="127.0.0.1", port=0, max_senders=2, admit_after=1, max_rate=1e6)
    try:
        pose = message("/puppetphone/orientation", 1.0, 0.0, 0.0, 0.0)
        src.handle_datagram(pose, "osc:10.0.0.1", now=1.0)  # admitted, on the candidates' budget
        src.drain()
        for _ in range(STEP_BUDGET[0] + 5):
            src.handle_datagram(pose, "osc:10.0.0.1", now=1.0)
        src.handle_datagram(b"x" * (MAX_DATAGRAM + 1), "osc:10.0.0.1", now=1.0)
        for _ in range(3):
            src.handle_datagram(b"junk", "osc:10.0.0.9", now=1.0)  # a candidate: the candidates' budget
        st = src.status()
        assert st.packets == 1 + STEP_BUDGET[0] and st.drop_reasons["oversize packet"] == 1
        assert st.drop_reasons["malformed packet"] == CANDIDATE_BUDGET[0]
        assert st.drop_reasons["over budget"] == 5 + 3 - CANDIDATE_BUDGET[0]
        src.drain()  # the next step: a fresh budget
        src.handle_datagram(pose, "osc:10.0.0.1", now=1.0)
        assert src.status().packets == STEP_BUDGET[0] + 2
        many = bundle(*[("/puppetphone/orientation", 1.0, 0.0, 0.0, 0.0)] * 30)
        for _ in range(3):
            src.handle_datagram(many, "osc:10.0.0.1", now=1.0)  # messages run out before datagrams do
        assert src.status().drop_reasons["over budget"] == 5 + 3 - CANDIDATE_BUDGET[0] + 2
    finally:
        src.stop()
