"""``puppetphone author flow [snowman|FILE]``: bend a scene's flow with sketched strokes (thesis ch. 3).

The scene opens from its camera; its SEcurves (blue) are computed once (a few seconds:
one contour search per group). Then:

- **left-drag**: sketch a flow curve — the objects nearby bend so their SEcurves follow
  it (their contacts kept: trees stay planted, parts stay together);
- **sketch a circle**: a centre-point; a network of flow curves converges on it;
  **drag the centre-point** (press on it) and the scene re-bends live;
- **Shift+left-drag**: draw an SEcurve of your own over objects;
- ``[`` / ``]``: narrower / wider grouping radius d_Max of the centre-point's network;
- ``Tab`` shows or hides the SEcurves; ``Ctrl+Z`` / ``Ctrl+Y`` undo / redo;
  ``Ctrl+S`` saves (``-o``, default ``<scene>.flow.json``); Esc quits.

A saved file reopens here (``author flow FILE``) and bends the game:
``puppetphone play snowman --flow FILE``. ``--script row|centre|demo`` performs the
thesis' kinds of edit with a scripted pointer (tests, screenshots, ``bench flow``'s
operations per edit: it prints the clicks and solve times) and saves at the end. ``--record FILE``
records the session (pointer and keys as tool operations, every step's state hash: the edits
and the bent scenery); ``puppetphone replay FILE --verify`` rebuilds the scene from the
recording and repeats the edits.
"""

from __future__ import annotations

import argparse
import base64
import hashlib
import math
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

__all__ = ["configure_flow", "run_flow", "FlowActivity", "open_flow", "script_events", "SCRIPTS", "FLOW_GAME",
           "replay_flow", "flow_digest"]

#: The name a flow session's recording gives as its game.
FLOW_GAME = "author-flow"

SCRIPTS = ("row", "centre", "demo")
_CENTRE_GRAB = 18.0  # pixels: a press this close to the centre-point drags it


def configure_flow(parser: argparse.ArgumentParser) -> None:
    """Add the ``author flow`` arguments."""
    from puppetphone.argtypes import output_file
    from puppetphone.runargs import add_run_arguments

    parser.add_argument("flow_scene", nargs="?", default="snowman", metavar="SCENE",
                        help="snowman (default), or a saved .flow.json file to go on editing")
    parser.add_argument("-o", "--output", type=output_file, default=None, help="where Ctrl+S saves (.json)")
    parser.add_argument("--script", choices=SCRIPTS, default=None,
                        help="a scripted pointer performs the edit (row: one stroke; centre: a centre-point "
                             "sketched then dragged; demo: both) and the result is saved")
    parser.add_argument("--record", type=output_file, default=None,
                        help="record the session (pointer, keys, every step's state) to replay it later")
    add_run_arguments(parser, screenshot_at=True)


def flow_setup(spec: str, size: tuple[int, int]):  # type: ignore[no-untyped-def]
    """``(scene, default output, edits to re-apply)`` of a named scene or a saved flow file (quick: no SEcurves yet)."""
    from authoring.flowcurves.storage import load_flow
    from engine.camera import OrbitCamera
    from games.snowman.bent_scenery import flow_scene

    path = Path(spec)
    if spec not in ("snowman", "tasbada") and (path.exists() or path.suffix == ".json"):
        doc = load_flow(path)
        if doc["scene"] != "snowman":
            raise ValueError(f"{path} bends the scene {doc['scene']!r}; this version opens the snowman field")
        scene = flow_scene(tuple(doc["size"]))
        cam = doc["camera"]
        scene.camera = OrbitCamera(target=cam["target"], yaw=cam["yaw"], pitch=cam["pitch"], distance=cam["distance"])
        return scene, path, doc["edits"]
    if spec == "tasbada":
        raise ValueError("tasbada has no flow scene yet: its props are drawn by the quest, not as static scenery")
    if spec != "snowman":
        raise ValueError(f"{spec!r} is neither a scene (snowman) nor a flow file")
    return flow_scene(size), Path("snowman.flow.json"), []


def build_session(scene, edits, progress=None, securves=None):  # type: ignore[no-untyped-def]
    """The session of ``scene`` (its SEcurves found, unless given: the slow part) with ``edits`` re-applied."""
    from authoring.flowcurves.session import FlowSession

    session = FlowSession(scene, securves=securves, progress=progress)
    for e in edits:
        session.add(e["kind"], e["points"], e["d_max"])
    return session


def open_flow(spec: str, size: tuple[int, int], progress=None):  # type: ignore[no-untyped-def]
    """A session of a named scene or of a saved flow file (its edits re-applied), and its default output."""
    scene, out, edits = flow_setup(spec, size)
    return build_session(scene, edits, progress), out


def _circle(centre: tuple[float, float], radius: float, n: int = 24) -> list[tuple[float, float]]:
    t = np.linspace(0.0, 2.0 * math.pi, n)
    return [(centre[0] + radius * math.cos(a), centre[1] + radius * math.sin(a)) for a in t]


def script_events(name: str) -> dict[int, list[tuple]]:
    """Pointer operations per step of a scripted edit (press, move, release), as a user would make them."""
    ops: dict[int, list[tuple]] = {}

    def drag(start: int, points: list[tuple[float, float]], shift: bool = False) -> int:
        ops.setdefault(start, []).append(("press", *points[0], shift))
        for k, p in enumerate(points[1:], 1):
            ops.setdefault(start + k, []).append(("move", *p))
        end = start + len(points)
        ops.setdefault(end, []).append(("release", *points[-1]))
        return end

    step = 10
    if name in ("row", "demo"):  # a stroke up beside the two back trees, leaning right as it rises
        ys = np.linspace(320.0, 150.0, 30)
        step = drag(step, [(535.0 + 0.004 * (320.0 - y) ** 2, float(y)) for y in ys]) + 20
    if name in ("centre", "demo"):  # a circle above the field, then the centre-point dragged right
        step = drag(step, _circle((640.0, 120.0), 22.0)) + 20
        path = [(640.0 + 4.0 * k, 120.0 + 1.0 * k) for k in range(0, 31, 3)]
        step = drag(step, path) + 10
    return ops


def flow_digest(activity) -> tuple[str, dict[str, bytes]]:  # type: ignore[no-untyped-def]
    """The session's state in parts: the edits, the bent scenery, the editor's own state (never a timing)."""
    from engine.hashing import combine_parts

    s = activity.session
    edits = hashlib.blake2b(b"edits", digest_size=16)
    for e in s.edits:
        edits.update(f"{e.kind}|{e.d_max!r}".encode())
        edits.update(np.ascontiguousarray(e.points, dtype=np.float64).tobytes())
    bent = hashlib.blake2b(b"bent", digest_size=16)
    for key in sorted(s.result.vertices):
        bent.update(str(key).encode())
        bent.update(np.ascontiguousarray(s.result.vertices[key], dtype=np.float64).tobytes())
    ui = hashlib.blake2b(b"editor", digest_size=16)
    stroke = np.asarray(activity.stroke or [], dtype=np.float64)
    ui.update(stroke.tobytes())
    ui.update(f"{activity.show_securves}|{activity.dragging_centre}|{activity.clicks}|{activity.strokes}".encode())
    return combine_parts([("edits", edits), ("bent", bent), ("editor", ui)])


class FlowActivity:
    """The flow editor as the runner's activity: pointer and keys reach it as tool operations through the hub.

    Operations (a hand's or a script's) are queued with the hub and applied at the next step,
    so a session records like a game and replays to the same bent scene. A replay saves nothing.
    """

    dt = 1.0 / 60.0

    def __init__(self, session, output: Path | None, script: str | None = None, *, hub=None,  # type: ignore[no-untyped-def]
                 recorder=None, check=None) -> None:  # fmt: skip
        from input.hub import InputHub

        from authoring.flowcurves.background import BackgroundSession

        # ``session`` may still be building on a thread: no input is applied and no step counted until it is whole.
        self.building = session if isinstance(session, BackgroundSession) else None
        self.session = None if self.building is not None else session
        self.output = output
        self.hub = hub if hub is not None else InputHub()
        self.recorder, self.check = recorder, check
        self.camera = session.scene.camera
        self.frame = 0
        self.script = script_events(script) if script else {}
        self.script_end = max(self.script) + 1 if self.script else 0
        self.stroke: list[tuple[float, float]] | None = None
        self.drawing_securve = False
        self.dragging_centre = False
        self.show_securves = True
        self.clicks, self.strokes = 0, 0
        self.solve_ms: list[float] = []
        self.message = ""

    def finished(self) -> bool:
        if self.check is not None and not self.check.ok:
            return True
        if self.session is None and self.building is not None and self.building.done():
            self._take_built()
            return self.session is None  # the build failed: its error is the message
        return self.hub.replay is not None and self.frame > self.hub.replay.last_frame

    def on_event(self, ev, runner) -> bool:  # type: ignore[no-untyped-def]
        """Pointer and keys become queued operations (Esc and P stay the runner's)."""
        import pygame

        if ev.type == pygame.MOUSEBUTTONDOWN and ev.button == 1:
            self.hub.tool("press", float(ev.pos[0]), float(ev.pos[1]), bool(pygame.key.get_mods() & pygame.KMOD_SHIFT))
        elif ev.type == pygame.MOUSEMOTION and ev.buttons[0]:
            self.hub.tool("move", float(ev.pos[0]), float(ev.pos[1]))
        elif ev.type == pygame.MOUSEBUTTONUP and ev.button == 1:
            self.hub.tool("release", float(ev.pos[0]), float(ev.pos[1]))
        elif ev.type == pygame.KEYDOWN and ev.key not in (pygame.K_ESCAPE, pygame.K_p):
            self.hub.tool("key", pygame.key.name(ev.key), bool(ev.mod & pygame.KMOD_CTRL))
        else:
            return False
        return True

    # -- operations ---------------------------------------------------------------------
    def _centre(self) -> np.ndarray | None:
        centres = [e for e in self.session.edits if e.kind == "centre"]
        return centres[-1].points[0] if centres else None

    def _timed(self, fn, *args) -> None:  # type: ignore[no-untyped-def]
        t0 = time.perf_counter()
        try:
            fn(*args)
        except ValueError as exc:
            self.message = str(exc)
            return
        self.solve_ms.append((time.perf_counter() - t0) * 1e3)

    def _release(self) -> None:
        from authoring.flowcurves.hermite import polyline_length

        pts = np.array(self.stroke or [], dtype=np.float64).reshape(-1, 2)
        self.stroke = None
        if len(pts) < 2 or polyline_length(pts) < 4.0:
            return
        self.strokes += 1
        length = polyline_length(pts)
        closed = length > 60.0 and np.linalg.norm(pts[-1] - pts[0]) < 0.2 * length
        if self.drawing_securve:
            self._timed(self.session.add, "securve", pts)
        elif closed:  # a circle: its centre of mass is the centre-point (§3.6)
            self._timed(self.session.add, "centre", pts.mean(axis=0, keepdims=True))
        else:
            self._timed(self.session.add, "stroke", pts)

    def apply(self, op: tuple) -> None:
        """One operation: press / move / release of the pointer, or a key."""
        kind = op[0]
        if kind == "press":
            self.clicks += 1
            centre = self._centre()
            self.dragging_centre = centre is not None and math.dist(centre, op[1:3]) < _CENTRE_GRAB
            self.drawing_securve = bool(op[3])
            self.stroke = None if self.dragging_centre else [(op[1], op[2])]
        elif kind == "move" and self.dragging_centre:
            self._timed(self.session.move_centre, [op[1], op[2]])
        elif kind == "move" and self.stroke is not None:
            self.stroke.append((op[1], op[2]))
        elif kind == "release":
            if self.stroke is not None:
                self.stroke.append((op[1], op[2]))
                self._release()
            self.dragging_centre = False
        elif kind == "key":
            self._key(op[1], op[2])

    def _key(self, name: str, ctrl: bool) -> None:
        s = self.session
        if ctrl and name == "z":
            self.message = "undone" if s.undo() else "nothing to undo"
        elif ctrl and name == "y":
            self.message = "redone" if s.redo() else "nothing to redo"
        elif ctrl and name == "s":
            if self.check is None:  # a replay saves nothing
                self.save()
        elif name == "tab":
            self.show_securves = not self.show_securves
        elif name in ("[", "]"):
            centres = [e for e in s.edits if e.kind == "centre"]
            if centres:
                centres[-1].d_max = max(10.0, centres[-1].d_max * (0.8 if name == "[" else 1.25))
                s.update()
                self.message = f"d_Max {centres[-1].d_max:.0f} px"

    def save(self) -> None:
        """Write the flow file (edits and deformed scenery) atomically."""
        from authoring.flowcurves.storage import save_flow

        from puppetphone.saving import save_or_say

        if self.output is not None:
            self.message = save_or_say(lambda path: save_flow(self.session, path), self.output)

    def _take_built(self) -> None:
        try:
            self.session = self.building.result()  # type: ignore[union-attr]
        except Exception as exc:  # noqa: BLE001 - the build's error, said once
            self.message = f"cannot find the SEcurves: {exc}"

    def step(self) -> None:
        if self.session is None:
            if self.building is None or not self.building.done():
                return  # still building: the hub keeps what was typed for the first real step
            self._take_built()
            if self.session is None:
                return
        for op in self.script.get(self.frame, []):
            self.hub.tool(*op)
        frame = self.hub.drain(self.frame)
        for op in frame.tool_operations():
            try:
                self.apply(tuple(op))
            except (IndexError, TypeError):
                raise ValueError(f"tool operation {list(op)} does not fit the flow editor") from None
        if self.script and self.frame + 1 == self.script_end:
            self.save()
        digest, parts = flow_digest(self)
        if self.recorder is not None:
            self.recorder.write(frame, digest, parts)
        if self.check is not None:
            self.check.check(self.frame, digest, parts)
        self.frame += 1

    def figures(self) -> str:
        """Clicks, strokes and solve times so far (operations of this session; no human study is compared)."""
        if self.session is None:
            return self.building.text if self.building is not None else ""
        r = self.session.result
        med = float(np.median(self.solve_ms)) if self.solve_ms else 0.0
        return (f"{len(self.session.edits)} edits, {self.strokes} strokes, {self.clicks} clicks; "
                f"update median {med:.0f} ms (last ARAP solve {r.solve_ms:.1f} ms after a {r.factor_ms:.0f} ms "
                f"factorisation), {len(r.vertices)} objects moved")

    def draw(self, scene, alpha: float, size: tuple[int, int]) -> None:  # type: ignore[no-untyped-def]
        from authoring.flowcurves.view import draw_objects, draw_session

        if self.session is None:  # the rest scene while its SEcurves are found, never a black window
            draw_objects(scene, self.building.scene.objects if self.building is not None else [])
        else:
            draw_session(scene, self.session, self.show_securves, self.stroke)
        scene.add_text("Flow Curves — drag: stroke · circle: centre-point · Shift+drag: SEcurve · "
                       "Ctrl+Z/Y undo/redo · Ctrl+S save · Tab SEcurves", size=16)
        scene.add_text(self.figures(), size=16)
        if self.message:
            scene.add_text(self.message, size=16, color=(1.0, 0.9, 0.5))


def run_flow(args: argparse.Namespace) -> int:
    """Open the scene, run the editor until the window closes (or ``--frames``)."""
    from authoring.flowcurves.storage import FlowFileError
    from engine.render.window import NoDisplayError
    from engine.runner import Runner
    from puppetphone.runargs import run_options

    runner = Runner(run_options(args, "PuppetPhone — Flow Curves"))
    try:
        runner.open()
    except NoDisplayError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2

    def progress(k: int, n: int, name: str) -> None:
        print(f"SEcurves: {k + 1}/{n} {name}", file=sys.stderr, flush=True)

    try:
        scene, default_out, edits = flow_setup(args.flow_scene, runner.size)
        if args.headless:  # no window to keep alive: build it here
            session = build_session(scene, edits, progress)
        else:  # the window opens on the rest scene and shows the progress while the SEcurves are found
            from authoring.flowcurves.background import BackgroundSession

            session = BackgroundSession(scene, lambda found: build_session(scene, edits, securves=found))
    except (ValueError, OSError, FlowFileError) as exc:
        runner.close()
        print(f"author flow: {exc}", file=sys.stderr)
        return 2
    recorder = None
    if args.record is not None:
        from input.recording import Recorder, RecordingHeader

        recorder = Recorder(args.record, RecordingHeader(game=FLOW_GAME, seed=0, dt=FlowActivity.dt, sources=["mouse"],
                                                         setup=_setup(args.flow_scene, runner.size)))  # fmt: skip
    activity = FlowActivity(session, args.output or default_out, args.script, recorder=recorder)
    runner.push_handlers(activity)
    try:
        result = runner.run(activity)
        if result.screenshot is not None:
            print(f"screenshot: {result.screenshot}")
        print(activity.figures())
        if activity.message:
            print(activity.message)
        if activity.session is None and activity.building is not None and activity.building.done():
            return 2  # the SEcurves could not be found: said above
    finally:
        runner.close()
        if activity.building is not None:
            activity.building.stop()
        if recorder is not None:
            recorder.close()
            print(f"recorded {recorder.frames} steps to {recorder.path}", file=sys.stderr)
    return 0


def _setup(spec: str, size: tuple[int, int]) -> dict[str, object]:
    """What a recording needs to rebuild the scene: a scene's name, or a flow file's bytes (never its path)."""
    setup: dict[str, object] = {"scene": spec, "size": list(size), "file": ""}
    if spec not in ("snowman", "tasbada"):
        setup["file"] = base64.b64encode(Path(spec).read_bytes()).decode()
    return setup


def replay_flow(recording, verify: bool = True) -> FlowActivity:  # type: ignore[no-untyped-def]
    """The recorded flow session, rebuilt from the recording alone, checking every step."""
    from input.hub import InputHub
    from input.replay import HashCheck, ReplaySource

    setup = recording.header.setup
    size = setup.get("size") if isinstance(setup, dict) else None
    if not (isinstance(size, list) and len(size) == 2
            and all(isinstance(v, int) and not isinstance(v, bool) and 0 < v <= 16384 for v in size)):
        raise ValueError("the recorded window size is not two whole numbers in 1..16384")
    if not isinstance(setup.get("scene"), str) or not isinstance(setup.get("file", ""), str):
        raise ValueError("the recorded flow scene is not text")
    if setup.get("file"):
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "recorded.flow.json"
            path.write_bytes(base64.b64decode(str(setup["file"])))
            session, _ = open_flow(str(path), (int(size[0]), int(size[1])))
    elif setup["scene"] == "snowman":
        session, _ = open_flow("snowman", (int(size[0]), int(size[1])))
    else:
        raise ValueError(f"the recording names the scene {str(setup['scene'])[:60]!r} without carrying it")
    return FlowActivity(session, None, hub=InputHub(replay=ReplaySource(recording)),
                        check=HashCheck(recording) if verify else None)  # fmt: skip
