"""A flood from loopback while a phone plays 600 paced steps: the phone still drives, the flood is counted.

The flood is what the issue's campaign found expensive: 62 KB bundles of poses, 8 KB
bundles of 64 messages that do get parsed, nested bundles and garbage, from two other
loopback addresses (127.0.0.2, 127.0.0.3) that stay *candidates* (``max_senders=3``), so
their datagrams are not refused as locked out but reach the size checks and the decoder.

Asserted on counts only (issue 37): 600 steps, not "10 s of wall clock", and no steps-per-second
floor (it failed at 53.3 steps/s on a loaded machine); the rate is printed for the log. The flood
runs until the steps are done and is then stopped, so it covers every step whatever the machine's load.
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
    port, seconds = int(sys.argv[1]), float(sys.argv[2])
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind(("127.0.0.1", 0))
    t0 = time.perf_counter()
    i = 0
    while (t := time.perf_counter() - t0) < seconds:
        yaw = 0.8 * math.sin(2 * math.pi * t / 4)   # sweep left and right every 4 s
        b = OscMessageBuilder("/puppetphone/orientation")
        for v in (math.cos(yaw / 2), 0.0, math.sin(yaw / 2), 0.0):
            b.add_arg(v, "f")
        sock.sendto(b.build().dgram, ("127.0.0.1", port))
        i += 1
        time.sleep(max(0.0, t0 + i / 60 - time.perf_counter()))
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


STEPS = 600


def _drops(src: OscSource) -> int:
    return sum(src.status().drop_reasons.values())


def test_a_flood_leaves_the_phone_driving_every_step():
    src = OscSource(host="127.0.0.1", port=0, max_senders=3)
    hub = InputHub([src]).start()
    app = App(seed=0)
    install_input(app, hub)
    GAME.install(app)
    phone = subprocess.Popen([sys.executable, "-c", PHONE, str(src.port), "600"])
    flood = None
    try:
        end = time.monotonic() + 30
        while app.world.query(Stick)[0][1].source != "osc:127.0.0.1" and time.monotonic() < end:
            app.step()
            time.sleep(1 / 60)
        assert app.world.query(Stick)[0][1].source == "osc:127.0.0.1", "the phone was not admitted"
        flood = subprocess.Popen(
            [sys.executable, "-c", FLOOD, str(src.port), "600", str(FLOOD_RATE)], stdout=subprocess.DEVNULL
        )
        end = time.monotonic() + 30
        while _drops(src) < 200 and time.monotonic() < end:  # the flood is under way
            time.sleep(0.05)
        assert _drops(src) >= 200, "the flood never reached the decoder"
        pacer = RealTimePacer(app.world.dt)
        with_phone, headings, late_drops = 0, [], 0
        t0 = time.perf_counter()
        for step in range(STEPS):
            pacer.wait()
            app.step()
            frame = app.world.resource(InputFrame)
            with_phone += frame.latest("osc:127.0.0.1") is not None
            d = app.world.query(Stick)[0][1].direction
            headings.append(float(np.arctan2(d[0], d[2])))
            if step == STEPS - 60:
                late_drops = _drops(src)
        rate = STEPS / (time.perf_counter() - t0)
        assert flood.poll() is None and _drops(src) > late_drops, "the flood stopped before the last second of steps"
    finally:
        if flood is not None:
            flood.kill()
            flood.wait(5)
        phone.kill()
        phone.wait(5)
        hub.close()
    st = src.status()
    print(
        f"flood: {STEPS} steps at {rate:.1f} steps/s (not asserted), phone samples in {with_phone}/{STEPS} steps, "
        f"drops {st.drop_reasons}"
    )
    # The phone's 60 Hz stream still reaches most steps (steps without one are clock jitter; before
    # the size and budget checks, a receiver busy decoding let 1 step in 100 see the phone).
    assert with_phone >= 0.6 * STEPS
    assert max(headings) > 0.6 and min(headings) < -0.6  # and its sweep still turns the stick
    for reason in ("oversize packet", "bundle too deep", "over budget", "non-unit quaternion"):
        assert st.drop_reasons.get(reason, 0) > 100, reason
