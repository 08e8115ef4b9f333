"""The phone as viewport: what the scene stream costs on the wire, how late it arrives, how fast the page draws.

- **Bytes per second** (no browser): the snowman demo (the shipped recording: a puppet
  rolling, stacking and carrying balls until two snowmen stand; its tracks in the snow
  and footprints included, each snowman is a puppet too) and the sandbox with
  50 wandering puppets are stepped; after every step the game's state drawing is
  quantised and delta-coded against the previous step exactly as a phone that keeps up
  gets it (:mod:`input.web.scene_stream`). Baseline: the same rows and the track grid
  sent whole as float32 each step (a straw man: streaming them without the codec).
- **Step → page latency** on loopback: a snowman session paced to real time streams to
  headless Chromium at 390×844. A *page frame* is counted two ways: **available** — the
  frame is decoded (in the page's stream worker) and has reached the thread that draws
  (the render worker), so the next animation frame can show it; and **drawn** — the
  draw calls of the first animation frame that shows that step have returned. The
  page also notes when the frame reached its stream worker and when it was decoded
  there. All are against the engine's publication time (end of the step); every clock
  is this machine's system clock.
  Under the bench's software compositing (``--disable-gpu``) each drawing holds the render
  worker until the rasteriser has finished the picture and it is read back (``GLES2::ReadPixels``
  in ``OffscreenCanvas::PushFrame``: 20-50 ms a drawing, most of the worker's time in a
  trace): a frame decoded meanwhile waits in that worker's queue, so *available* − *decoded* is
  the drawing's cadence, not a queue of frames (at most 4 are in flight to the drawer). GPU
  compositing on SwiftShader frees the worker, but the display then shows about half the
  drawings (a trace counts the ``Display::DrawAndSwap``), so the bench keeps software compositing.
- **Step → client latency** on loopback, the same session with a Python WebSocket client
  in place of the browser (it decodes and acknowledges at once): the engine's and the
  network's part of the latency, without the page's main thread.
- **Page frame rate** at 390×844 in headless Chromium's software WebGL2 (SwiftShader),
  the median of the page's one-second counts while the stream runs: first with the
  drawing held at full resolution (every device pixel: the goal is judged there), then
  with the page free to lower its resolution when it cannot hold 40 fps, to no less than
  0.75 a side (the resolution it settled at is reported too, and the page shows it). The latencies cover both halves. Since a loaded
  machine's frame rate says more about the load than the page, the CPU time Chromium
  (all its processes: the page's threads and the software rasteriser) spends per
  frame drawn at full resolution is reported too: ``1000 / that`` is the frame rate
  one free core would give.
"""

from __future__ import annotations

import os
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from puppetphone.bench.figures import Figure

if TYPE_CHECKING:
    from engine.app import App
    from engine.ecs import World
    from engine.render.scene import RenderScene

__all__ = ["PageLatency", "client_latency", "page_latency", "run", "stream_bytes"]

STEP_MS = 1000.0 / 60.0
PHONE = (390, 844)


def _stream_cost(app: App, draw: Callable[[World, RenderScene, float], None], steps: int) -> tuple[float, float, int]:
    """Mean coded and raw float32 bytes per step over ``steps`` steps, and the puppets seen."""
    from engine.components import Puppet
    from engine.render.scene import RenderScene
    from input.web.scene_stream import KINDS, CameraPose, SceneState, encode_frame, quantise

    cam = CameraPose((0.0, 1.5, 4.0), (1.0, 0.0, 0.0, 0.0), 60.0)
    scene, prev = RenderScene(), SceneState.empty()
    coded = raw = 0
    for i in range(steps):
        app.step()
        scene.clear()
        draw(app.world, scene, 1.0)
        state = quantise(scene, app.world.frame, 0.0, cam)
        if i > 0:  # the first is the GLB a phone gets once
            coded += len(encode_frame(prev, state))
            raw += sum(getattr(scene, k).data.nbytes for k in KINDS) + 32
            raw += scene.marks.amount.nbytes if scene.marks is not None else 0
        prev = state
    return coded / (steps - 1), raw / (steps - 1), len(app.world.query(Puppet))


def stream_bytes(demo_steps: int = 1800, crowd_steps: int = 600) -> dict[str, float]:
    """Coded and raw bytes per step for the snowman demo and a 50-puppet crowd."""
    import games.snowman
    from games.common import draw_world
    from games.snowman.draw import draw_snowman_state
    from input.hub import InputHub
    from input.recording import read_recording
    from input.replay import replay_hub
    from puppetphone.games import load_game, make_app

    demo = Path(games.snowman.__path__[0]) / "demo.rec"
    rec = read_recording(demo)
    app = make_app("snowman", rec.header.seed, replay_hub(rec), load_game("snowman").replay_setup(rec.header.setup))
    s_coded, s_raw, s_puppets = _stream_cost(app, draw_snowman_state, min(demo_steps, len(rec.frames)))
    crowd = make_app("sandbox", 1, InputHub(), {"puppets": 50})
    c_coded, c_raw, puppets = _stream_cost(crowd, draw_world, crowd_steps)
    return {
        "snowman_coded": s_coded,
        "snowman_raw": s_raw,
        "snowman_puppets": float(s_puppets),
        "crowd_coded": c_coded,
        "crowd_raw": c_raw,
        "crowd_puppets": float(puppets),
    }


@dataclass(frozen=True)
class PageLatency:
    """Per step after the first two seconds, ms from the engine's publication (end of the step) to: the frame
    reaching the page's stream worker, decoded there, available to the thread that draws, and first drawn
    (the draw calls of the first animation frame showing it have returned); and the page's drawing."""

    received_ms: np.ndarray
    decoded_ms: np.ndarray
    available_ms: np.ndarray
    drawn_ms: np.ndarray
    fps: float
    fps_full: float
    cpu_ms_per_frame_full: float
    resolution: float
    frames: int
    steps: int
    where: str


def _tree_cpu_seconds(pid: int) -> float:
    """User and system CPU seconds of process ``pid`` and all its descendants so far (Linux ``/proc``)."""
    tick = os.sysconf("SC_CLK_TCK")
    stats: dict[int, tuple[int, float]] = {}
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()
        except OSError:  # the process ended meanwhile
            continue
        stats[int(entry.name)] = (int(fields[1]), (int(fields[11]) + int(fields[12])) / tick)
    tree, total, grew = {pid}, 0.0, True
    while grew:
        new = {p for p, (parent, _) in stats.items() if parent in tree and p not in tree}
        tree |= new
        grew = bool(new)
    for p in tree:
        total += stats.get(p, (0, 0.0))[1]
    return total


def page_latency(steps: int = 840) -> PageLatency:
    """Publication → receipt, decoding, availability and first drawing of each step on the page, and its fps."""
    from engine.pacing import RealTimePacer
    from input.hub import InputHub
    from input.web.cert import load_or_create
    from input.web.server import WebSource
    from puppetphone.bench.chromium import Chromium
    from puppetphone.session import build_activity

    with tempfile.TemporaryDirectory(prefix="pp-view-bench-") as folder:
        src = WebSource(port=0, certificate=load_or_create([], Path(folder)), max_rate=1000.0)
        hub = InputHub([src]).start()
        activity = build_activity("snowman", 0, hub)
        try:
            with Chromium() as browser:
                browser.enable_sensors()
                browser.open(src.url(), *PHONE)
                browser.wait_for("document.getElementById('state').textContent.startsWith('connected: web:1')")
                browser.click("enable")
                browser.wait_for("!document.getElementById('calib').hidden")
                browser.click("calib-ok")
                browser.evaluate("ppView.holdResolution(1)")
                pacer = RealTimePacer(activity.dt, wake=hub.arrived)
                fps: list[float] = []
                full: list[float] = []
                half = steps // 2
                for i in range(steps):
                    pacer.wait()
                    activity.step()
                    if i == 150:
                        cpu0, drawn0 = _tree_cpu_seconds(browser.proc.pid), int(browser.evaluate("ppView.drawn"))
                    if i == half:
                        cpu = _tree_cpu_seconds(browser.proc.pid) - cpu0
                        cpu_per_frame = 1000.0 * cpu / max(int(browser.evaluate("ppView.drawn")) - drawn0, 1)
                        browser.evaluate("ppView.holdResolution(null)")
                    if i % 60 == 0 and 120 < i < half:
                        full.append(float(browser.evaluate("ppView.fps")))
                    elif i % 60 == 0 and i > half + 120:
                        fps.append(float(browser.evaluate("ppView.fps")))
                time.sleep(0.3)
                report = browser.evaluate("ppView.report()")
                received, drawn, frames = report["log"], report["drawLog"], report["frames"]
                resolution = float(browser.evaluate("ppView.resolution"))
                where = browser.evaluate("ppView.where")
        finally:
            activity.close()
    published = {int(row[0]): row[1] for row in received}
    late = np.array([row for row in received if row[0] > 120])
    draw = np.array([t - published[s] for s, t in drawn if s in published and s > 120])
    return PageLatency(
        late[:, 2] - late[:, 1],
        late[:, 3] - late[:, 1],
        late[:, 4] - late[:, 1],
        draw,
        float(np.median(fps)),
        float(np.median(full)),
        cpu_per_frame,
        resolution,
        int(frames),
        steps,
        str(where),
    )


def client_latency(steps: int = 600) -> np.ndarray:
    """Publication → receipt (ms) of each frame by a Python client that acknowledges every frame at once."""
    import json
    import ssl
    import threading

    from websockets.sync.client import connect

    from engine.pacing import RealTimePacer
    from input.hub import InputHub
    from input.web.cert import load_or_create
    from input.web.scene_glb import read_scene_glb
    from input.web.scene_stream import decode_frame
    from input.web.server import WebSource
    from puppetphone.session import build_activity

    tls = ssl.create_default_context()
    tls.check_hostname, tls.verify_mode = False, ssl.CERT_NONE  # loopback, the engine's own certificate
    latencies: list[float] = []
    with tempfile.TemporaryDirectory(prefix="pp-view-bench-") as folder:
        src = WebSource(port=0, certificate=load_or_create([], Path(folder)), max_rate=1000.0)
        hub = InputHub([src]).start()
        activity = build_activity("snowman", 0, hub)
        stop = threading.Event()

        def client() -> None:
            with connect(f"wss://127.0.0.1:{src.port}/ws?t={src.token}", ssl=tls, max_size=None) as ws:
                ws.recv()  # hello
                state = None
                while not stop.is_set():
                    try:
                        data = ws.recv(timeout=0.5)
                    except TimeoutError:
                        continue
                    now = time.time()
                    assert isinstance(data, bytes), "the engine sends scene frames as binary messages"
                    state = read_scene_glb(data)[1] if state is None else decode_frame(state, data)
                    ws.send(json.dumps({"ack": state.step}))
                    if state.published and state.step > 120:
                        latencies.append(1000.0 * (now - state.published))

        th = threading.Thread(target=client, daemon=True)
        th.start()
        try:
            pacer = RealTimePacer(activity.dt, wake=hub.arrived)
            for _ in range(steps):
                pacer.wait()
                activity.step()
        finally:
            stop.set()
            th.join(2.0)
            activity.close()
    return np.array(latencies)


def run() -> list[Figure]:
    """Stream bytes per second (snowman, 50 puppets), step → page latency p50/p99 and page fps."""
    from puppetphone.bench.chromium import find_chromium

    b = stream_bytes()
    per_s = 60.0
    figures = [
        Figure(
            "phone-view",
            "snowman_stream_kb_per_s",
            b["snowman_coded"] * per_s / 1000,
            "KB/s",
            "raw float32 rows (straw man)",
            b["snowman_raw"] * per_s / 1000,
        ),
        Figure(
            "phone-view",
            "snowman_bytes_per_puppet_step",
            b["snowman_coded"] / b["snowman_puppets"],
            "B",
            "raw float32 rows (straw man)",
            b["snowman_raw"] / b["snowman_puppets"],
        ),
        Figure(
            "phone-view",
            "crowd50_stream_kb_per_s",
            b["crowd_coded"] * per_s / 1000,
            "KB/s",
            "raw float32 rows (straw man)",
            b["crowd_raw"] * per_s / 1000,
        ),
        Figure(
            "phone-view",
            "crowd50_bytes_per_puppet_step",
            b["crowd_coded"] / b["crowd_puppets"],
            "B",
            "raw float32 rows (straw man)",
            b["crowd_raw"] / b["crowd_puppets"],
        ),
    ]
    net = client_latency()
    figures += [
        Figure("phone-view", "step_to_client_p50_ms", float(np.percentile(net, 50)), "ms", "two steps", 2 * STEP_MS),
        Figure("phone-view", "step_to_client_p99_ms", float(np.percentile(net, 99)), "ms", "two steps", 2 * STEP_MS),
    ]
    if find_chromium() is None:
        print("phone-view: no chromium (apt-get install chromium): the page figures are left out")
        return figures
    lat = page_latency()
    out = []
    for name, values in (
        ("page_decoded", lat.decoded_ms),
        ("page_available", lat.available_ms),
        ("page_drawn", lat.drawn_ms),
    ):
        for q in (50, 99):
            out.append(
                Figure(
                    "phone-view",
                    f"step_to_{name}_p{q}_ms",
                    float(np.percentile(values, q)),
                    "ms",
                    "two steps",
                    2 * STEP_MS,
                )
            )
    return (
        figures
        + out
        + [
            Figure("phone-view", "page_fps_390x844_full_resolution", lat.fps_full, "fps", "goal", 30.0),
            Figure(
                "phone-view",
                "page_cpu_ms_per_frame_full_resolution",
                lat.cpu_ms_per_frame_full,
                "ms",
                "a 30 fps budget",
                1000.0 / 30.0,
            ),
            Figure("phone-view", "page_fps_390x844_adaptive", lat.fps, "fps", "goal", 30.0),
            Figure("phone-view", "page_resolution_scale_adaptive", lat.resolution, "ratio", "full resolution", 1.0),
            Figure("phone-view", "frames_sent_per_step", lat.frames / lat.steps, "ratio", "one per step", 1.0),
        ]
    )
