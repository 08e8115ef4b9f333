"""The ``author flow [SCENE|FILE]`` tool: bend a scene's flow with sketched strokes (thesis ch. 3), as a session's simulation.

Beside :mod:`authoring.flowcurves` (the solver and its scenes). The scene opens from its
camera; its SEcurves are found once (a few seconds; on a thread while a window shows the
rest scene). Left-drag sketches a flow curve, a sketched circle is a centre-point (a press
on it drags it), Shift+left-drag draws an SEcurve; ``[`` ``]`` the grouping radius, Tab
the SEcurves, Ctrl+Z/Y undo/redo, Ctrl+S saves. ``script`` performs the thesis' kinds of
edit with a scripted pointer and saves at the end. A recording keeps the scene's name or
the flow file's bytes; a replay rebuilds the scene and repeats the edits.
"""

from __future__ import annotations

import base64
import hashlib
import math
import tempfile
import time
from collections.abc import Callable, Iterable, Mapping
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from authoring.bindings import orbit_camera
from authoring.operations import Key, Move, Operation, Orbit, Press, Release, Zoom
from authoring.session import Ending, Opened, Script, ToolKind, ToolSimulation
from engine.camera import Camera
from engine.render.scene import RenderScene
from input.sample import InputFrame

if TYPE_CHECKING:
    from authoring.flowcurves.background import BackgroundSession
    from authoring.flowcurves.scene import FlowScene
    from authoring.flowcurves.securves import SECurve
    from authoring.flowcurves.session import FlowSession

__all__ = [
    "FLOW_GAME",
    "SCRIPTS",
    "FlowTool",
    "Scenes",
    "flow_digest",
    "flow_tool",
    "open_flow",
    "open_live",
    "reopen_flow",
    "script_events",
]

#: The name a flow session's recording gives as its game.
FLOW_GAME = "author-flow"

SCRIPTS = ("row", "centre", "demo")
#: The scenes the tool can open, by name: each builds its scene for a window size.
Scenes = Mapping[str, Callable[[tuple[int, int]], "FlowScene"]]
#: The SEcurve search's progress: ``(group done, groups, group name)``.
Progress = Callable[[int, int, str], None]
_CENTRE_GRAB = 18.0  # pixels: a press this close to the centre-point drags it


def flow_setup(spec: str, size: tuple[int, int], scenes: Scenes) -> tuple[FlowScene, Path, list[dict[str, Any]]]:
    """``(scene, default output, edits to re-apply)`` of a named scene or a saved flow file (quick: no SEcurves yet).

    ``scenes`` are the scenes a game offers by name (the launcher wires them: a tool never imports a game)."""
    from authoring.flowcurves.storage import load_flow
    from engine.camera import OrbitCamera

    path = Path(spec)
    if spec not in scenes and (path.exists() or path.suffix == ".json"):
        doc = load_flow(path)
        if doc["scene"] not in scenes:
            raise ValueError(f"{path} bends the scene {doc['scene']!r}; this version opens {', '.join(scenes)}")
        scene = scenes[doc["scene"]](tuple(doc["size"]))
        cam = doc["camera"]
        scene.camera = OrbitCamera(target=cam["target"], yaw=cam["yaw"], pitch=cam["pitch"], distance=cam["distance"])
        return scene, path, doc["edits"]
    if spec not in scenes:
        raise ValueError(f"{spec!r} is neither a scene ({', '.join(scenes)}) nor a flow file")
    return scenes[spec](size), Path(f"{spec}.flow.json"), []


def build_session(
    scene: FlowScene,
    edits: Iterable[Mapping[str, Any]],
    progress: Progress | None = None,
    securves: list[SECurve] | None = None,
) -> FlowSession:
    """The session of ``scene`` (its SEcurves found, unless given: the slow part) with ``edits`` re-applied."""
    from authoring.flowcurves.session import FlowSession

    session = FlowSession(scene, securves=securves, progress=progress)
    for e in edits:
        session.add(e["kind"], e["points"], e["d_max"])
    return session


def open_flow(
    spec: str, size: tuple[int, int], scenes: Scenes, progress: Progress | None = None
) -> tuple[FlowSession, Path]:
    """A session of a named scene or of a saved flow file (its edits re-applied), and its default output."""
    scene, out, edits = flow_setup(spec, size, scenes)
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


def flow_digest(activity: FlowTool) -> tuple[str, dict[str, bytes]]:
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


class FlowTool(ToolSimulation):
    """The flow editor as a session's simulation; a replay saves nothing.

    ``script`` names a scripted edit (:func:`script_events`): its operations are the
    session's script (:meth:`script_steps`), and the result is saved after its last step.
    """

    def __init__(self, session: Any, output: Path | None, script: str | None = None) -> None:
        from authoring.flowcurves.background import BackgroundSession

        # ``session`` may still be building on a thread: no input is applied and no step counted until it is whole.
        self.building = session if isinstance(session, BackgroundSession) else None
        self.session: Any = None if self.building is not None else session
        self.output = output
        self._camera = session.scene.camera
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

    @property
    def camera(self) -> Camera:
        """The scene's camera."""
        return self._camera

    def ready(self) -> bool:
        """Whole once its SEcurves are found (in a window they are found on a thread)."""
        if self.session is None and self.building is not None and self.building.done():
            self._take_built()
        return self.session is not None

    def ended(self) -> bool:
        """The SEcurves could not be found: the build's error is the message."""
        return self.session is None and self.building is not None and self.building.done()

    def script_steps(self) -> Script:
        """The scripted edit's operations, step by step."""
        return ([list(op) for op in self.script.get(k, [])] for k in range(self.script_end))

    # -- operations ---------------------------------------------------------------------
    def _centre(self) -> np.ndarray | None:
        centres = [e for e in self.session.edits if e.kind == "centre"]
        return centres[-1].points[0] if centres else None

    def _timed(self, fn: Callable[..., object], *args: object) -> None:
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

    def apply(self, op: Operation) -> None:
        """One operation: press / move / release of the pointer (Shift: an SEcurve), the camera, or a key."""
        if isinstance(op, Press):
            self.clicks += 1
            centre = self._centre()
            self.dragging_centre = centre is not None and math.dist(centre, (op.x, op.y)) < _CENTRE_GRAB
            self.drawing_securve = op.shift
            self.stroke = None if self.dragging_centre else [(op.x, op.y)]
        elif isinstance(op, Move) and self.dragging_centre:
            self._timed(self.session.move_centre, [op.x, op.y])
        elif isinstance(op, Move) and self.stroke is not None:
            self.stroke.append((op.x, op.y))
        elif isinstance(op, Release):
            if self.stroke is not None and op.x is not None and op.y is not None:
                self.stroke.append((op.x, op.y))
                self._release()
            self.stroke, self.dragging_centre = None, False
        elif isinstance(op, Orbit):
            orbit_camera(self._camera, op)
        elif isinstance(op, Zoom):
            self._camera.zoom(op.factor)
        elif isinstance(op, Key):
            self._key(op.name, op.ctrl)

    def _key(self, name: str, ctrl: bool) -> None:
        s = self.session
        if ctrl and name == "z":
            self.message = "undone" if s.undo() else "nothing to undo"
        elif ctrl and name == "y":
            self.message = "redone" if s.redo() else "nothing to redo"
        elif ctrl and name == "s":
            self.save()  # (a replay has no output: it saves nothing)
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
        from authoring.saving import save_or_say

        if self.output is not None:
            self.message = save_or_say(lambda path: save_flow(self.session, path), self.output)

    def _take_built(self) -> None:
        assert self.building is not None  # (called only while a build runs)
        try:
            self.session = self.building.result()
        except Exception as exc:  # noqa: BLE001 - the build's error, said once
            self.message = f"cannot find the SEcurves: {exc}"

    def advance(self, frame: InputFrame) -> None:
        """The edits are made by the operations; a scripted edit is saved after its last step."""
        if self.script and frame.frame + 1 == self.script_end:
            self.save()
        self.frame = frame.frame + 1

    def digest(self) -> tuple[str, dict[str, bytes]]:
        """:func:`flow_digest`."""
        return flow_digest(self)

    def close(self) -> None:
        """Stop a build still running."""
        if self.building is not None:
            self.building.stop()

    def conclude(self) -> Ending:
        """The figures and the last message; exit 2 when the SEcurves could not be found."""
        lines = [self.figures()] + ([self.message] if self.message else [])
        return Ending(lines, 2 if self.ended() else 0)

    def figures(self) -> str:
        """Clicks, strokes and solve times so far (operations of this session; no human study is compared)."""
        if self.session is None:
            return self.building.text if self.building is not None else ""
        r = self.session.result
        med = float(np.median(self.solve_ms)) if self.solve_ms else 0.0
        return (
            f"{len(self.session.edits)} edits, {self.strokes} strokes, {self.clicks} clicks; "
            f"update median {med:.0f} ms (last ARAP solve {r.solve_ms:.1f} ms after a {r.factor_ms:.0f} ms "
            f"factorisation), {len(r.vertices)} objects moved"
        )

    def draw(self, scene: RenderScene, alpha: float, size: tuple[int, int]) -> None:
        from authoring.flowcurves.view import draw_objects, draw_session

        if self.session is None:  # the rest scene while its SEcurves are found, never a black window
            draw_objects(scene, self.building.scene.objects if self.building is not None else [])
        else:
            draw_session(scene, self.session, self.show_securves, self.stroke)
        scene.add_text(
            "Flow Curves — drag: stroke · circle: centre-point · Shift+drag: SEcurve · "
            "Ctrl+Z/Y undo/redo · Ctrl+S save · Tab SEcurves",
            size=16,
        )
        scene.add_text(self.figures(), size=16)
        if self.message:
            scene.add_text(self.message, size=16, color=(1.0, 0.9, 0.5))


def _setup(spec: str, size: tuple[int, int], scenes: Scenes) -> dict[str, object]:
    """What a recording needs to rebuild the scene: a scene's name, or a flow file's bytes (never its path)."""
    setup: dict[str, object] = {"scene": spec, "size": list(size), "file": ""}
    if spec not in scenes:
        setup["file"] = base64.b64encode(Path(spec).read_bytes()).decode()
    return setup


def open_live(options: Mapping[str, Any], size: tuple[int, int], scenes: Scenes) -> Opened:
    """A live session: ``flow_scene``, ``output``, ``script``; ``headless`` builds the SEcurves here
    (``progress`` is told each group), a window builds them on a thread while it shows the rest scene."""
    spec = str(options.get("flow_scene", "snowman"))
    scene, default_out, edits = flow_setup(spec, size, scenes)
    session: FlowSession | BackgroundSession
    if options.get("headless"):
        session = build_session(scene, edits, options.get("progress"))
    else:
        from authoring.flowcurves.background import BackgroundSession

        session = BackgroundSession(scene, lambda found: build_session(scene, edits, securves=found))
    output = options.get("output")
    tool = FlowTool(session, Path(output) if output else default_out, options.get("script"))
    return Opened(tool, _setup(spec, size, scenes), tool.script_steps() if tool.script else None, tool.conclude)


def reopen_flow(setup: object, scenes: Scenes) -> FlowTool:
    """The recorded flow session, rebuilt from its set-up alone (a flow file's bytes, never its path)."""
    size = setup.get("size") if isinstance(setup, dict) else None
    if not (
        isinstance(setup, dict)
        and isinstance(size, list)
        and len(size) == 2
        and all(isinstance(v, int) and not isinstance(v, bool) and 0 < v <= 16384 for v in size)
    ):
        raise ValueError("the recorded window size is not two whole numbers in 1..16384")
    if not isinstance(setup.get("scene"), str) or not isinstance(setup.get("file", ""), str):
        raise ValueError("the recorded flow scene is not text")
    if setup.get("file"):
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "recorded.flow.json"
            path.write_bytes(base64.b64decode(str(setup["file"])))
            session, _ = open_flow(str(path), (int(size[0]), int(size[1])), scenes)
    elif setup["scene"] in scenes:
        session, _ = open_flow(str(setup["scene"]), (int(size[0]), int(size[1])), scenes)
    else:
        raise ValueError(f"the recording names the scene {str(setup['scene'])[:60]!r} without carrying it")
    return FlowTool(session, None)


def flow_tool(scenes: Scenes) -> ToolKind:
    """The flow tool over the scenes a game offers by name (``puppetphone.flow_scenes`` wires the snowman field)."""
    return ToolKind(
        FLOW_GAME, "PuppetPhone — Flow Curves", partial(open_live, scenes=scenes), partial(reopen_flow, scenes=scenes)
    )
