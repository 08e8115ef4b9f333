"""Which of the page's threads draws, and that the others leave the cores alone (headless Chromium).

The render worker draws the magic window into the canvas the page hands it; where a canvas cannot be
handed to a worker (no ``transferControlToOffscreen``), the page's main thread draws instead. The main
thread's animation-frame loop runs only then: idle, it cost a style/layout/commit frame every 16.7 ms
on the cores the software rasteriser and the stream need (bench phone-view, issue 33). Break it: a
main-thread loop started in every case fails the first test's count; one never started leaves the
second test's page undrawn.
"""

from __future__ import annotations

import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

from puppetphone.bench.chromium import Chromium, find_chromium

pytestmark = pytest.mark.skipif(
    find_chromium() is None, reason="no chromium executable: apt-get install chromium (.ci/run installs it)"
)

# Counts the main thread's animation-frame requests (installed before the page's scripts run).
COUNT_FRAMES = (
    "window.__frames = 0; { const raf = window.requestAnimationFrame.bind(window);"
    " window.requestAnimationFrame = (f) => { window.__frames += 1; return raf(f); }; }"
)
NO_OFFSCREEN = "delete HTMLCanvasElement.prototype.transferControlToOffscreen;"


@contextmanager
def snowman_page(before_load: str, steps: int) -> Iterator[Chromium]:
    """A calibrated phone page on a snowman session paced for ``steps`` steps; ``before_load`` runs in the
    page before its own scripts."""
    from engine.pacing import RealTimePacer
    from input.hub import InputHub
    from input.web.cert import load_or_create
    from input.web.server import WebSource
    from puppetphone.session import build_activity

    with tempfile.TemporaryDirectory(prefix="pp-threads-") as folder:
        src = WebSource(port=0, certificate=load_or_create([], Path(folder)))
        hub = InputHub([src]).start()
        activity = build_activity("snowman", 0, hub)
        try:
            with Chromium() as browser:
                browser.call("Page.enable")
                browser.call("Page.addScriptToEvaluateOnNewDocument", source=before_load)
                browser.enable_sensors()
                browser.open(src.url(), 390, 844)
                browser.wait_for("document.getElementById('state').textContent.startsWith('connected: web:1')")
                browser.click("enable")
                browser.wait_for("!document.getElementById('calib').hidden")
                browser.click("calib-ok")
                pacer = RealTimePacer(activity.dt, wake=hub.arrived)
                for _ in range(steps):
                    pacer.wait()
                    activity.step()
                yield browser
        finally:
            activity.close()


def test_while_the_render_worker_draws_the_main_thread_runs_no_animation_frames() -> None:
    with snowman_page(COUNT_FRAMES, 240) as browser:
        browser.wait_for("ppView.drawn > 5", timeout=30)
        assert browser.evaluate("ppView.where") == "render worker"
        before = int(browser.evaluate("window.__frames"))
        for _ in range(20):  # about a second, polled
            browser.evaluate("ppView.drawn")
        drawn = int(browser.evaluate("ppView.drawn"))
        frames = int(browser.evaluate("window.__frames"))
    assert drawn > 5, "the render worker did not draw"
    assert frames <= 1 and frames == before, f"{frames} animation frames asked for on the main thread"


def test_a_canvas_that_cannot_go_to_a_worker_is_drawn_by_the_main_thread() -> None:
    with snowman_page(NO_OFFSCREEN, 240) as browser:
        assert browser.evaluate("ppView.where") == "main thread"
        browser.wait_for("ppView.drawn > 5 && ppView.step > 100", timeout=30)
        first = int(browser.evaluate("ppView.drawn"))
        browser.wait_for(f"ppView.drawn > {first + 3}", timeout=30)
