"""The ``author curves`` tool: a keyframed clip's poses, motion curves and timing, as a session's simulation.

Beside :mod:`authoring.curves_scene` (which turns pixels and key names into edits). A
recording keeps the clip's bytes and keys (never a path), so a replay reopens the same
clip and repeats the operations. ``--script drag|walk`` is a scripted animator: the
operations of each step, as a hand would make them (:mod:`authoring.keypose_script`).
"""

from __future__ import annotations

import base64
import hashlib
import tempfile
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from authoring.bindings import orbit_camera
from authoring.operations import Key, Operation, Orbit, Resize, Zoom, encode
from authoring.session import Ending, KeyUse, Opened, ToolKind, ToolSimulation
from engine.camera import Camera
from engine.render.scene import RenderScene
from input.hub import InputHub
from input.sample import InputFrame

if TYPE_CHECKING:
    from authoring.curves_scene import CurvesScene
    from authoring.keyframe_curves.session import CurveSession

__all__ = ["CURVES_GAME", "SCRIPTS", "TOOL", "CurvesTool", "curves_digest", "open_curves", "reopen_curves"]

#: The name a curves session's recording gives as its game.
CURVES_GAME = "author-curves"
SCRIPTS = ("drag", "walk")


def _drag_script(scene: CurvesScene) -> Iterator[list[list[object]]]:
    """Pin both feet over the whole clip, then drag the left hand's trajectory at frame 15 up and forward."""
    from authoring.keypose_script import goto_frame

    names = scene.session.clip.skeleton.names
    for joint in ("l_foot", "r_foot", "l_hand"):
        while joint in names and scene.joint != joint:
            yield [["key", "tab", False, False]]
        if joint != "l_hand":
            yield [["key", "p", False, True]]
    yield from goto_frame(scene, 15)
    x, y = (round(float(v), 2) for v in scene.camera.project(scene.trajectory()[15][None], *scene.size)[0])
    yield [["press", x, y, False]]
    for i in range(1, 21):
        k = i / 20.0
        yield [["move", round(x - 35.0 * k, 2), round(y - 40.0 * k, 2)]]
    yield [["release", round(x - 35.0, 2), round(y - 40.0, 2)]]


def curves_digest(activity: CurvesTool) -> tuple[str, dict[str, bytes]]:
    """The session's state in parts: the curves, the holds, the viewport."""
    from engine.hashing import combine_parts

    scene = activity.scene
    c = scene.session.clip.curves
    h = hashlib.blake2b(b"curves", digest_size=16)
    for a in (c.times, c.values, c.out_x, c.out_y, c.in_x, c.in_y):
        h.update(np.ascontiguousarray(a, dtype=np.float64).tobytes())
    holds = hashlib.blake2b(repr(scene.session.holds).encode(), digest_size=16)
    cam = scene.camera
    v = hashlib.blake2b(b"scene", digest_size=16)
    v.update(np.array([scene.frame, cam.yaw, cam.pitch, cam.distance, *np.asarray(cam.target, dtype=np.float64),
                       *scene.size], dtype=np.float64).tobytes())  # fmt: skip
    v.update(f"{scene.joint}|{scene.session.revision}|{len(scene.session.history)}".encode())
    return combine_parts([("curves", h), ("holds", holds), ("scene", v)])


class CurvesTool(ToolSimulation):
    """The curves scene as a session's simulation (a replay saves nothing)."""

    def __init__(
        self, scene: Any, output: Path | None = None, exports: list[Path] | None = None, save_at_end: bool = False
    ) -> None:
        self.scene, self.output = scene, output
        self.exports, self.save_at_end = list(exports or []), save_at_end

    @property
    def camera(self) -> Camera:
        """The scene's orbit camera."""
        return self.scene.camera

    def on_key(self, key: Key, hub: InputHub) -> KeyUse:
        """Every key is the scene's (P pins, . steps a frame) but Ctrl+P, the runner's pause."""
        return "pass" if key.name == "p" and key.ctrl else "queue"

    def apply(self, op: Operation) -> None:
        """Size, Ctrl+S (save), the camera; the rest is the scene's."""
        s = self.scene
        if isinstance(op, Resize):
            s.size = (op.width, op.height)
        elif isinstance(op, Key) and op.ctrl and op.name == "s":
            self.save()
        elif isinstance(op, Orbit):
            orbit_camera(s.camera, op)
        elif isinstance(op, Zoom):
            s.camera.zoom(op.factor)
        else:
            s.apply(encode(op))

    def save(self) -> None:
        """Save the clip and its keys (when the session has an output: a replay has none)."""
        from authoring.keyframe_curves.session import save_curves
        from authoring.saving import save_or_say

        if self.output is not None:
            self.scene.message = save_or_say(lambda path: save_curves(self.scene.session.clip, path), self.output)

    def advance(self, frame: InputFrame) -> None:
        """One step of the scene."""
        self.scene.step(self.dt)

    def digest(self) -> tuple[str, dict[str, bytes]]:
        """:func:`curves_digest`."""
        return curves_digest(self)

    def draw(self, scene: RenderScene, alpha: float, size: tuple[int, int]) -> None:
        """The curves scene."""
        self.scene.draw(scene)

    def conclude(self) -> Ending:
        """Save (``-o``) and export at the end of a live session; the edits made."""
        from authoring.mocurves import export_clip
        from engine.io.formats import FORMATS
        from engine.io.gltf_cubic import write_gltf_cubic

        lines = []
        clip = self.scene.session.clip
        if self.save_at_end:
            self.save()
            lines.append(self.scene.message)
        for path in self.exports:
            if path.suffix.lower() in FORMATS["gltf"].suffixes:
                write_gltf_cubic(path, clip)  # keys and tangents, CUBICSPLINE
            else:
                export_clip(clip.bake(), path)  # BVH and .ppclip are sampled
            lines.append(f"exported {path}")
        history = self.scene.session.history
        lines.append(f"edits: {len(history)} ({'; '.join(history) or 'none'})")
        return Ending(lines)


def open_curves(options: Mapping[str, Any], size: tuple[int, int]) -> Opened:
    """A live session: ``clip``, ``output``, ``export``, ``joint``, ``every``, ``duration``, ``script``."""
    from authoring.curves_scene import CurvesScene
    from authoring.keyframe_curves.session import CurveSession
    from authoring.keypose_script import walk_script
    from authoring.mocurves.storage import EXPORT_SUFFIXES

    exports = [Path(p) for p in options.get("export") or []]
    for path in exports:
        if path.suffix.lower() not in EXPORT_SUFFIXES:
            raise ValueError(f"cannot export {path}: use one of {', '.join(EXPORT_SUFFIXES)}")
    clip = str(options["clip"])
    session = CurveSession.from_spec(clip, options.get("every"), float(options.get("duration", 1.0)))
    scene = CurvesScene(session, size, str(options.get("joint", "l_hand")))
    setup = _setup(options, size)
    scene.character = _character(setup)
    output = options.get("output")
    tool = CurvesTool(
        scene,
        Path(output) if output else Path(f"{Path(clip).stem}_curves.ppclip"),
        exports,
        save_at_end=output is not None,
    )
    script = options.get("script")
    steps = None if script is None else (walk_script(scene) if script == "walk" else _drag_script(scene))
    return Opened(tool, setup, steps, tool.conclude)


def reopen_curves(setup: object) -> CurvesTool:
    """The recorded session, rebuilt from its set-up alone."""
    from authoring.curves_scene import CurvesScene

    session, size, joint = _reopen(setup)
    scene = CurvesScene(session, size, joint)
    scene.character = _character(setup)
    return CurvesTool(scene)


def _character(setup: object) -> Any:
    """The set-up's ``--character``, rebuilt from its bytes (``None`` without one; one-line ``ValueError``)."""
    from engine.character.setup import decode

    value = setup.get("character") if isinstance(setup, dict) else None
    return None if value is None else decode(value)


def _setup(options: Mapping[str, Any], size: tuple[int, int]) -> dict[str, object]:
    """What a recording needs to reopen the same session: the clip's bytes (and keys), never its path."""
    from authoring.keyframe_curves.session import keys_path

    setup: dict[str, object] = {"clip": options["clip"], "size": list(size), "joint": options.get("joint", "l_hand"),
                                "every": options.get("every") or 0, "duration": float(options.get("duration", 1.0))}  # fmt: skip
    if options.get("character"):  # the --character file's bytes, as play carries them
        from engine.character.setup import character_setup

        setup["character"] = character_setup(str(options["character"]))
    path = Path(str(options["clip"]))
    if path.suffix.lower() == ".ppclip":
        setup["name"] = path.name
        setup["ppclip"] = base64.b64encode(path.read_bytes()).decode()
        keys = keys_path(path)
        setup["keys"] = base64.b64encode(keys.read_bytes()).decode() if keys.exists() else ""
    return setup


def _reopen(setup: object) -> tuple[CurveSession, tuple[int, int], str]:
    """The recorded session, from the recording alone (a path in it is never opened); one-line ``ValueError``."""
    from authoring.keyframe_curves.session import REST, CurveSession, keys_path
    from engine.clips import default_clips

    if not isinstance(setup, dict):
        raise ValueError("the recorded curves set-up is not an object")
    size = setup.get("size")
    if not (
        isinstance(size, list)
        and len(size) == 2
        and all(isinstance(v, int) and not isinstance(v, bool) and 0 < v <= 16384 for v in size)
    ):
        raise ValueError("the recorded window size is not two whole numbers in 1..16384")
    for key, kind in (("clip", str), ("joint", str), ("every", int), ("duration", float)):
        if not isinstance(setup.get(key), kind) or isinstance(setup.get(key), bool):
            raise ValueError(f"the recorded {key} is not {kind.__name__}")
    every = int(setup["every"]) or None
    if setup.get("ppclip"):
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / Path(str(setup.get("name", "clip.ppclip"))).name
            path.write_bytes(base64.b64decode(str(setup["ppclip"])))
            if setup.get("keys"):
                keys_path(path).write_bytes(base64.b64decode(str(setup["keys"])))
            session = CurveSession.from_spec(str(path), every)
    elif setup["clip"] == REST or setup["clip"] in default_clips():
        session = CurveSession.from_spec(str(setup["clip"]), every, float(setup["duration"]))
    else:
        raise ValueError(f"the recording names the clip {str(setup['clip'])[:80]!r} without carrying it")
    return session, (int(size[0]), int(size[1])), str(setup["joint"])


TOOL = ToolKind(CURVES_GAME, "PuppetPhone — Motion Curves", open_curves, reopen_curves)
