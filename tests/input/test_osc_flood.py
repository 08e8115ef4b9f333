"""A flood from loopback while a phone sends 900 readings at 60 Hz: they reach the steps, the flood is counted.

The flood is what the issue's campaign found expensive: 62 KB bundles of poses, 8 KB
bundles of 64 messages that do get parsed, nested bundles and garbage, from two other
loopback addresses (127.0.0.2, 127.0.0.3) that stay *candidates* (``max_senders=3``), so
their datagrams are not refused as locked out but reach the size checks and the decoder.

Asserted on counts only (issue 37): the phone's readings that reached a step against the number it sent,
not "10 s of wall clock", nor steps that saw the phone, nor a steps-per-second floor (each failed on a
loaded machine). The flood runs until the phone has sent everything and is then stopped, so it covers
every reading whatever the machine's load.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap
import time

import numpy as np

from engine.app import App
from engine.components import Stick
from engine.pacing import RealTimePacer
from games.sandbox import GAME
from input.hub import InputHub
from input.osc import OscSource
from input.plugin import install_input
from input.sample import InputFrame

PHONE = textwrap.dedent("""
    import math, socket, sys, time
    from pythonosc.osc_message_builder import OscMessageBuilder
    port, count = int(sys.argv[1]), int(sys.argv[2])
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind(("127.0.0.1", 0))
    t0 = time.perf_counter()
    i = 0
    while i < count:
        t = time.perf_counter() - t0
        yaw = 0.8 * math.sin(2 * math.pi * t / 4)   # sweep left and right every 4 s
        b = OscMessageBuilder("/puppetphone/orientation")
        for v in (math.cos(yaw / 2), 0.0, math.sin(yaw / 2), 0.0):
            b.add_arg(v, "f")
        sock.sendto(b.build().dgram, ("127.0.0.1", port))
        i += 1
        time.sleep(max(0.0, t0 + i / 60 - time.perf_counter()))
    print(i)
""")

FLOOD = textwrap.dedent("""
    import socket, sys, time
    from pythonosc.osc_bundle_builder import OscBundleBuilder, IMMEDIATELY
    from pythonosc.osc_message_builder import OscMessageBuilder
    port, seconds, rate = int(sys.argv[1]), float(sys.argv[2]), float(sys.argv[3])
    def bundle(n, addr="/puppetphone/pose", args=(0.1, 0.2, 0.3, 1.0, 0.0, 0.0, 0.0)):
        bb = OscBundleBuilder(IMMEDIATELY)
        for _ in range(n):
            b = OscMessageBuilder(addr)
            for a in args:
                b.add_arg(a, "f")
            bb.add_content(b.build())
        return bb.build()
    huge = bundle(960).dgram                                                      # ~62 KB of valid poses
    parsed = bundle(12, "/puppetphone/orientation", (2.0, 0.0, 0.0, 0.0)).dgram   # decoded, all rejected
    outer = OscBundleBuilder(IMMEDIATELY); inner = bundle(2)
    for _ in range(3):
        bb = OscBundleBuilder(IMMEDIATELY); bb.add_content(inner); inner = bb.build()
    nested = inner.dgram
    packets = [huge, parsed, nested, b"\\x00garbage\\xff" * 50]
    socks = []
    for host in ("127.0.0.2", "127.0.0.3"):
        s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM); s.bind((host, 0)); s.setblocking(False); socks.append(s)
    t0, sent = time.perf_counter(), 0
    while (t := time.perf_counter() - t0) < seconds:
        for _ in range(40):
            try:
                socks[sent % 2].sendto(packets[sent % 4], ("127.0.0.1", port))
            except OSError:  # the receiver's buffer is full, or it has gone
                pass
            sent += 1
        time.sleep(max(0.0, t0 + sent / rate - time.perf_counter()))
    print(sent)
""")

FLOOD_RATE = 4000  # datagrams/s, a quarter of them 62 KB: ~70 MB/s, more than a LAN delivers to a laptop


PHONE_READINGS = 900  # 15 s at 60 Hz: admission, the flood's start, then ~12 s of steps under the flood


def _drops(src: OscSource) -> int:
    return sum(src.status().drop_reasons.values())


def test_a_flood_loses_few_of_the_phones_readings_and_the_phone_still_steers():
    """Counted against what the phone sent, not against steps or wall time: a starved phone process sends late,
    not less, so a loaded machine no longer fails it (at load 24 the old "phone in ≥ 60 % of steps" saw 325/600)."""
    src = OscSource(host="127.0.0.1", port=0, max_senders=3)
    hub = InputHub([src]).start()
    app = App(seed=0)
    install_input(app, hub)
    GAME.install(app)
    # One step before the phone starts: the first imports numba and loads the cached kernels (0.9-2.3 s under load). A
    # phone already sending through that stall lost every reading past the step's budget of 8 ("over budget":
    # 36-66 of 900 beside two busy loops, the 107 short once in CI likely the same), a cost of the test's
    # start-up, not of the flood; the kernel's receive buffer lost 0-28 of them meanwhile.
    app.step()
    phone = subprocess.Popen(
        [sys.executable, "-c", PHONE, str(src.port), str(PHONE_READINGS)], stdout=subprocess.PIPE, text=True
    )
    flood = None
    pacer = RealTimePacer(app.world.dt)
    received, headings, drops_by_step = 0, [], []

    def step() -> None:
        nonlocal received
        pacer.wait()
        app.step()
        received += len(app.world.resource(InputFrame).samples_of("osc:127.0.0.1"))

    try:
        end = time.monotonic() + 30
        while app.world.query(Stick)[0][1].source != "osc:127.0.0.1" and time.monotonic() < end:
            step()
        assert app.world.query(Stick)[0][1].source == "osc:127.0.0.1", "the phone was not admitted"
        flood = subprocess.Popen(
            [sys.executable, "-c", FLOOD, str(src.port), "600", str(FLOOD_RATE)], stdout=subprocess.DEVNULL
        )
        end = time.monotonic() + 30
        while _drops(src) < 200 and time.monotonic() < end:  # the flood is under way
            step()
        assert _drops(src) >= 200, "the flood never reached the decoder"
        end = time.monotonic() + 300  # a deadline, not an assertion: the phone ends after its readings
        while phone.poll() is None and time.monotonic() < end:
            step()
            d = app.world.query(Stick)[0][1].direction
            headings.append(float(np.arctan2(d[0], d[2])))
            drops_by_step.append(_drops(src))
        assert phone.poll() is not None, "the phone did not end"
        sent = int(phone.communicate()[0])
        for _ in range(30):  # what the hub still holds
            step()
        assert len(drops_by_step) > 60, "the phone had ended before the flood was under way"
        assert flood.poll() is None and _drops(src) > drops_by_step[-60], "the flood stopped before the phone did"
    finally:
        if flood is not None:
            flood.kill()
            flood.wait(5)
        if phone.poll() is None:
            phone.kill()
        phone.communicate(timeout=5)  # reaps it and closes its pipe
        hub.close()
    st = src.status()
    print(
        f"flood: {received}/{sent} phone readings reached the steps over {len(headings)} flooded steps, "
        f"drops {st.drop_reasons}"
    )
    # Before the size and budget checks, a receiver busy decoding let 1 step in 100 see the phone.
    assert received >= 0.9 * sent
    assert max(headings) > 0.6 and min(headings) < -0.6  # and its sweep still turns the stick
    for reason in ("oversize packet", "bundle too deep", "over budget", "non-unit quaternion"):
        assert st.drop_reasons.get(reason, 0) > 100, reason
