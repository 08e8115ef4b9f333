"""Input latency: OSC send time → the 60 Hz step in which the sample is applied.

A sender thread streams ``/puppetphone/pose`` over loopback UDP at about 60 Hz
(slightly off the step rate, so every phase between packet and step occurs) and
remembers each packet's send time; the simulation, paced to real time by
:class:`engine.pacing.RealTimePacer`, records when each packet's sample reaches the
``Stick`` (the end of the step whose ``InputFrame`` carried it). The goal is within
one step: 16.7 ms.
"""

from __future__ import annotations

import threading
import time

import numpy as np

from puppetphone.bench.figures import Figure

__all__ = ["run", "measure"]


def measure(steps: int = 240, dt: float = 1.0 / 60.0) -> np.ndarray:
    """Latencies in seconds of every packet that was applied during ``steps`` steps."""
    from pythonosc.udp_client import SimpleUDPClient

    from engine.app import App
    from engine.components import Stick
    from engine.pacing import RealTimePacer
    from input.hub import InputHub
    from input.osc import OscSource
    from input.plugin import install_input
    from input.sample import InputFrame

    src = OscSource(host="127.0.0.1", port=0, max_rate=10_000)
    hub = InputHub([src]).start()
    app = App(seed=0, dt=dt)
    install_input(app, hub)
    sent: dict[int, float] = {}
    stop = threading.Event()

    def sender() -> None:
        client = SimpleUDPClient("127.0.0.1", src.port)
        seq = 0
        while not stop.is_set():
            sent[seq] = time.perf_counter()
            client.send_message("/puppetphone/pose", [float(seq), 1.0, 0.0, 1.0, 0.0, 0.0, 0.0])
            seq += 1
            time.sleep(1.0 / 59.0)

    th = threading.Thread(target=sender, daemon=True)
    th.start()
    pacer = RealTimePacer(dt, wake=hub.arrived)  # as in play: a packet may start its step early
    latencies = []
    try:
        for _ in range(steps):
            pacer.wait()
            app.step()
            applied = time.perf_counter()
            assert app.world.query(Stick)
            for s in app.world.resource(InputFrame).samples:
                seq = int(s.position[0]) if s.position is not None else -1
                if seq in sent:
                    latencies.append(applied - sent[seq])
    finally:
        stop.set()
        th.join(1.0)
        hub.close()
    return np.array(latencies)


def run() -> list[Figure]:
    """``osc_latency_p50_ms`` and ``osc_latency_p99_ms`` against one 60 Hz step; the web controller's
    ``web_latency_p50_ms`` and ``web_latency_p99_ms`` (:mod:`puppetphone.bench.web_latency`) when Chromium is there."""
    from puppetphone.bench.chromium import find_chromium
    from puppetphone.bench.web_latency import measure as measure_web

    lat = measure() * 1000.0
    step_ms = 1000.0 / 60.0
    figures = [
        Figure("input-latency", "osc_latency_p50_ms", float(np.percentile(lat, 50)), "ms", "one step", step_ms),
        Figure("input-latency", "osc_latency_p99_ms", float(np.percentile(lat, 99)), "ms", "one step", step_ms),
        Figure("input-latency", "osc_packets_applied", float(len(lat)), "count"),
    ]
    if find_chromium() is None:
        print("input-latency: no chromium (apt-get install chromium): the web controller figures are left out")
        return figures
    web = measure_web() * 1000.0
    return figures + [
        Figure("input-latency", "web_latency_p50_ms", float(np.percentile(web, 50)), "ms", "one step", step_ms),
        Figure("input-latency", "web_latency_p99_ms", float(np.percentile(web, 99)), "ms", "one step", step_ms),
        Figure("input-latency", "web_readings_applied", float(len(web)), "count"),
    ]
