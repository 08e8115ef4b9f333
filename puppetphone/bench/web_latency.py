"""Web controller latency: a sensor change in the page → the 60 Hz step that applies it.

Headless Chromium (:mod:`puppetphone.bench.chromium`) opens the controller page served by a real
:class:`input.web.server.WebSource` on loopback; a driver thread changes the emulated
orientation sensor about 60 times a second. The page stamps each reading with its own
clock at the sensor event (``performance.timeOrigin + performance.now()``, the same
system clock as :func:`time.time` on this machine) and the simulation, paced to real
time, notes when each reading's sample has been applied to the ``Stick`` (the end of
the step whose ``InputFrame`` carried it). The goal is within one step: 16.7 ms.

A reading may start its step up to half a step early (:class:`engine.pacing.RealTimePacer`'s
``wake``), as in ``play``: Chromium delivers sensor events on its own 60 Hz tick, so with
slots alone the latency is whatever phase the two clocks happened to start at (1 to 22 ms
from run to run here). The first ``warmup`` steps are not counted.
"""

from __future__ import annotations

import tempfile
import threading
import time
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from engine.app import App
    from engine.components import Stick as _Stick
    from engine.pacing import RealTimePacer
    from input.sample import InputFrame as _InputFrame
    from input.web.server import WebSource

__all__ = ["measure"]


def measure(steps: int = 300, dt: float = 1.0 / 60.0, warmup: int = 60, wake: bool = True) -> np.ndarray:
    """Latencies in seconds of every reading applied during ``steps`` paced steps.

    Raises:
        bench.chromium.ChromiumError: no Chromium, or it did not load the page.
    """
    from engine.app import App
    from engine.components import Stick
    from engine.pacing import RealTimePacer
    from input.hub import InputHub
    from input.plugin import install_input
    from input.sample import InputFrame
    from input.web.cert import load_or_create
    from input.web.server import WebSource
    from puppetphone.bench.chromium import Chromium

    with tempfile.TemporaryDirectory(prefix="pp-web-bench-") as folder:
        src = WebSource(port=0, certificate=load_or_create([], Path(folder)), max_rate=1000.0)
        hub = InputHub([src]).start()
        app = App(seed=0, dt=dt)
        install_input(app, hub)
        stop = threading.Event()
        try:
            with Chromium() as browser:
                browser.enable_sensors()
                browser.open(src.url())
                browser.wait_for("document.getElementById('state').textContent.startsWith('connected: web:1')")
                browser.click("enable")
                browser.wait_for("document.getElementById('mode').textContent.includes('orientation')")

                def driver() -> None:
                    i = 0
                    while not stop.is_set():
                        browser.orientation(20.0 * np.sin(i / 30.0), -10.0 + (i % 2) * 0.5, 0.0)
                        i += 1
                        time.sleep(1.0 / 61.0)

                th = threading.Thread(target=driver, daemon=True)
                th.start()
                pacer = RealTimePacer(dt, wake=hub.arrived if wake else None)
                latencies = _run(app, src, steps, warmup, pacer, InputFrame, Stick)
                stop.set()
                th.join(2.0)
        finally:
            stop.set()
            hub.close()
    return np.array(latencies)


def _run(
    app: App,
    src: WebSource,
    steps: int,
    warmup: int,
    pacer: RealTimePacer,
    InputFrame: type[_InputFrame],  # the classes, imported lazily by the caller
    Stick: type[_Stick],
) -> list[float]:
    out = []
    for k in range(warmup + steps):
        pacer.wait()
        app.step()
        applied = time.time() * 1000.0
        assert app.world.query(Stick)
        if k < warmup:
            continue
        for s in app.world.resource(InputFrame).samples:
            page = src.page_times.get(s.time)
            if page is not None and page > 0:
                out.append((applied - page) / 1000.0)
    return out
