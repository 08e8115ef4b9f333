"""``puppetphone author curves CLIP``: key poses and motion curves of a keyframed clip (thesis ch. 4).

``CLIP`` is ``rest`` (a new looping clip holding the rest pose, ``--duration`` seconds), a
default clip's name (``walk``, ``run``, …; keyed every ``--every`` frames, default 6) or a
``.ppclip`` (with its ``.ppkeys`` side file when it has one, else keyed every ``--every``,
default 3, which reproduces its frames). Ctrl+S saves the baked clip and its keys
atomically to ``--output`` (default ``<name>_curves.ppclip``); ``--export`` writes glTF
(keys and tangents as CUBICSPLINE), BVH or ppclip (the baked clip) at the end.
``--headless --frames N --screenshot PNG`` runs without a window; ``--script drag`` plays
a scripted gesture (pin both feet, drag the left hand's trajectory at frame 15) and
``--script walk`` the scripted animator of :mod:`authoring.keypose_script` (a walk cycle
from four key poses, then one drag of the hand's path). ``--record FILE`` records the
session — pointer and keys as tool operations, every step's state hash — and
``puppetphone replay FILE --verify`` reopens the same clip from the recording and
repeats the edits. The same runner and conventions as ``author edit``.
"""

from __future__ import annotations

import argparse
import base64
import hashlib
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path

import numpy as np

__all__ = ["configure_curves", "run_curves", "CurvesActivity", "replay_curves", "curves_digest", "CURVES_GAME"]

#: The name a curves session's recording gives as its game.
CURVES_GAME = "author-curves"


def configure_curves(parser: argparse.ArgumentParser) -> None:
    """Add the ``author curves`` arguments."""
    from puppetphone.argtypes import output_file
    from puppetphone.runargs import add_run_arguments

    parser.add_argument("clip", help="rest (a new clip), a default clip name (walk, run, …) or a .ppclip")
    parser.add_argument("-o", "--output", type=Path, default=None, help="where Ctrl+S saves (.ppclip + .ppkeys)")
    parser.add_argument("--export", type=Path, action="append", default=[],
                        help="also write the baked clip here on exit (.ppclip, .bvh, .glb, .gltf); repeatable")  # fmt: skip
    parser.add_argument("--joint", default="l_hand", help="the joint whose trajectory is shown (default l_hand)")
    parser.add_argument("--every", type=int, default=None, help="key a clip without keys every N frames (N ≥ 3)")
    parser.add_argument("--duration", type=float, default=1.0, help="rest: the new clip's length in seconds")
    parser.add_argument("--script", choices=("drag", "walk"), default=None, help="a scripted animator instead of a hand")
    parser.add_argument("--record", type=output_file, default=None,
                        help="record the session (pointer, keys, every step's state) to replay it later")
    add_run_arguments(parser)


def _drag_script(scene) -> Iterator[list[list[object]]]:  # type: ignore[no-untyped-def]
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


def curves_digest(activity) -> tuple[str, dict[str, bytes]]:  # type: ignore[no-untyped-def]
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


class CurvesActivity:
    """The curves scene as the runner's activity; pointer and keys reach it as tool operations through the hub.

    Operations are queued by :meth:`on_event` (or a script) and applied at the next step, so
    a session records like a game and replays to the same curves. A replay saves nothing.
    """

    dt = 1.0 / 60.0

    def __init__(self, scene, output: Path | None, hub, script: str | None = None, *,  # type: ignore[no-untyped-def]
                 recorder=None, check=None) -> None:  # fmt: skip
        from authoring.keypose_script import walk_script

        self.scene, self.output, self.hub = scene, output, hub
        self.recorder, self.check = recorder, check
        self.camera = scene.camera
        self.frame = 0
        self._orbiting = False
        self._pending: list[object] | None = None
        self._script = None if script is None else (walk_script(scene) if script == "walk" else _drag_script(scene))

    def finished(self) -> bool:
        if self.check is not None and not self.check.ok:
            return True
        return self.hub.replay is not None and self.frame > self.hub.replay.last_frame

    def _queue(self, op: list[object]) -> None:
        """Queue a tool operation; pointer moves and orbits are merged to one per step."""
        if op[0] in ("move", "orbit"):
            if op[0] == "orbit" and self._pending is not None and self._pending[0] == "orbit":
                op = ["orbit", self._pending[1] + op[1], self._pending[2] + op[2]]  # type: ignore[operator]
            elif self._pending is not None and self._pending[0] != op[0]:
                self._flush()
            self._pending = op
            return
        self._flush()
        self.hub.tool(*op)

    def _flush(self) -> None:
        if self._pending is not None:
            self.hub.tool(*self._pending)
            self._pending = None

    def on_event(self, ev, runner) -> bool:  # type: ignore[no-untyped-def]
        import pygame

        try:
            mods = ev.mod if ev.type == pygame.KEYDOWN else pygame.key.get_mods()
        except pygame.error:
            mods = 0
        shift, ctrl = bool(mods & pygame.KMOD_SHIFT), bool(mods & pygame.KMOD_CTRL)
        pointer = (pygame.MOUSEBUTTONDOWN, pygame.MOUSEBUTTONUP, pygame.MOUSEMOTION, pygame.MOUSEWHEEL)
        if self._script is not None and (ev.type in pointer or (ev.type == pygame.KEYDOWN and ev.key != pygame.K_ESCAPE)):
            return True  # a script is the hand: the real pointer (a window opening under it) must not join in
        if ev.type == pygame.MOUSEBUTTONDOWN and ev.button in (1, 3):
            self._queue(["press", ev.pos[0], ev.pos[1], shift or ev.button == 3])
        elif ev.type == pygame.MOUSEBUTTONDOWN and ev.button == 2:
            self._orbiting = True
        elif ev.type == pygame.MOUSEBUTTONUP and ev.button in (1, 3):
            self._queue(["release", ev.pos[0], ev.pos[1]])
        elif ev.type == pygame.MOUSEBUTTONUP and ev.button == 2:
            self._orbiting = False
        elif ev.type == pygame.MOUSEMOTION:
            self._queue(["orbit", ev.rel[0], ev.rel[1]] if self._orbiting else ["move", ev.pos[0], ev.pos[1]])
        elif ev.type == pygame.MOUSEWHEEL:
            self._queue(["zoom", 0.9 if ev.y > 0 else 1.1])
        elif ev.type in (pygame.VIDEORESIZE, pygame.WINDOWSIZECHANGED) and runner is not None:
            self._queue(["size", *runner.size])
        elif ev.type == pygame.KEYDOWN and ev.key not in (pygame.K_ESCAPE, pygame.K_p if ctrl else -1):
            self._queue(["key", pygame.key.name(ev.key), ctrl, shift])
        else:
            return False
        return True

    def _apply(self, op: tuple) -> None:
        from authoring.keyframe_curves.session import save_curves
        from puppetphone.saving import save_or_say

        s, kind = self.scene, op[0]
        if kind == "size":
            s.size = (int(op[1]), int(op[2]))
        elif kind == "key" and op[2] and op[1] == "s":
            if self.output is not None:
                s.message = save_or_say(lambda path: save_curves(s.session.clip, path), self.output)
        else:
            s.apply(op)

    def save(self) -> None:
        """Save now (the end of a ``--output`` run)."""
        from authoring.keyframe_curves.session import save_curves
        from puppetphone.saving import save_or_say

        if self.output is not None:
            self.scene.message = save_or_say(lambda path: save_curves(self.scene.session.clip, path), self.output)

    def step(self) -> None:
        if self._script is not None:
            for op in next(self._script, []):
                self.hub.tool(*op)
        self._flush()
        frame = self.hub.drain(self.frame)
        for op in frame.tool_operations():
            try:
                self._apply(op)
            except (IndexError, TypeError, KeyError):
                raise ValueError(f"tool operation {list(op)} does not fit the curves scene") from None
        self.scene.step(self.dt)
        digest, parts = curves_digest(self)
        if self.recorder is not None:
            self.recorder.write(frame, digest, parts)
        if self.check is not None:
            self.check.check(self.frame, digest, parts)
        self.frame += 1

    def draw(self, scene, alpha: float, size: tuple[int, int]) -> None:  # type: ignore[no-untyped-def]
        self.scene.draw(scene)


def _setup(args: argparse.Namespace, size: tuple[int, int]) -> dict[str, object]:
    """What a recording needs to reopen the same session: the clip's bytes (and keys), never its path."""
    from authoring.keyframe_curves.session import keys_path

    setup: dict[str, object] = {"clip": args.clip, "size": list(size), "joint": args.joint,
                                "every": args.every or 0, "duration": float(args.duration)}  # fmt: skip
    path = Path(args.clip)
    if path.suffix.lower() == ".ppclip":
        setup["name"] = path.name
        setup["ppclip"] = base64.b64encode(path.read_bytes()).decode()
        keys = keys_path(path)
        setup["keys"] = base64.b64encode(keys.read_bytes()).decode() if keys.exists() else ""
    return setup


def _reopen(setup: object):  # type: ignore[no-untyped-def]
    """The recorded session, from the recording alone (a path in it is never opened); one-line ``ValueError``."""
    from authoring.keyframe_curves.session import REST, CurveSession, keys_path
    from engine.clips import default_clips

    if not isinstance(setup, dict):
        raise ValueError("the recorded curves set-up is not an object")
    size = setup.get("size")
    if not (isinstance(size, list) and len(size) == 2
            and all(isinstance(v, int) and not isinstance(v, bool) and 0 < v <= 16384 for v in size)):
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


def replay_curves(recording, verify: bool = True) -> CurvesActivity:  # type: ignore[no-untyped-def]
    """The recorded curves session, rebuilt from the recording alone, checking every step."""
    from authoring.curves_scene import CurvesScene
    from input.hub import InputHub
    from input.replay import HashCheck, ReplaySource

    session, size, joint = _reopen(recording.header.setup)
    return CurvesActivity(CurvesScene(session, size, joint), None, InputHub(replay=ReplaySource(recording)),
                          check=HashCheck(recording) if verify else None)  # fmt: skip


def run_curves(args: argparse.Namespace) -> int:
    """Open the clip, run the scene until the window closes (or ``--frames``), export."""
    from authoring.curves_scene import CurvesScene
    from authoring.keyframe_curves.session import CurveSession
    from authoring.mocurves import export_clip
    from authoring.mocurves.storage import EXPORT_SUFFIXES
    from engine.io.formats import FORMATS
    from engine.io.gltf_cubic import write_gltf_cubic
    from engine.render.window import NoDisplayError
    from engine.runner import Runner
    from input.hub import InputHub
    from input.recording import Recorder, RecordingHeader
    from puppetphone.runargs import run_options

    for path in args.export:
        if path.suffix.lower() not in EXPORT_SUFFIXES:
            print(f"error: cannot export {path}: use one of {', '.join(EXPORT_SUFFIXES)}", file=sys.stderr)
            return 2
    try:
        session = CurveSession.from_spec(args.clip, args.every, args.duration)
    except (ValueError, OSError) as exc:
        print(f"cannot open {args.clip!r}: {exc}", file=sys.stderr)
        return 2
    runner = Runner(run_options(args, "PuppetPhone — Motion Curves"))
    try:
        runner.open()
    except NoDisplayError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    output = args.output or Path(f"{Path(args.clip).stem}_curves.ppclip")
    recorder = None
    if args.record is not None:
        recorder = Recorder(args.record, RecordingHeader(game=CURVES_GAME, seed=0, dt=CurvesActivity.dt,
                                                         sources=["mouse"], setup=_setup(args, runner.size)))  # fmt: skip
    scene = CurvesScene(session, runner.size, args.joint)
    activity = CurvesActivity(scene, output, InputHub(), args.script, recorder=recorder)
    runner.push_handlers(activity)
    try:
        result = runner.run(activity)
        if result.screenshot is not None:
            print(f"screenshot: {result.screenshot}")
        if args.output is not None:
            activity.save()
            print(f"saved {args.output}")
        for path in args.export:
            if path.suffix.lower() in FORMATS["gltf"].suffixes:
                write_gltf_cubic(path, session.clip)  # keys and tangents, CUBICSPLINE
            else:
                export_clip(session.clip.bake(), path)  # BVH and .ppclip are sampled
            print(f"exported {path}")
        print(f"edits: {len(session.history)} ({'; '.join(session.history) or 'none'})")
    finally:
        runner.close()
        if recorder is not None:
            recorder.close()
            print(f"recorded {recorder.frames} steps to {recorder.path}", file=sys.stderr)
    return 0
