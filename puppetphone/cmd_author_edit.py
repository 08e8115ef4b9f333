"""``puppetphone author edit CLIP``: refine a cycle with MoCurves while it plays.

``CLIP`` is a ``.ppclip`` file (a recorded cycle; its ``.mocurves.json`` side file is
picked up), a BVH/glTF/GLB motion file (opened as its loop, see
:mod:`authoring.motion_loop`; ``--animation``, ``--units``, ``--joint-map``, ``--retarget``)
or the name of a default clip (``walk``, ``run``, …). Ctrl+S saves atomically
to ``--output`` (default: beside the input, ``<name>_edited.ppclip``); ``--export`` writes
BVH/glTF/ppclip copies at the end. ``--headless --frames N --screenshot PNG`` runs the
scene without a window (CI, screenshots). Wired as ``configure_edit``/``run_edit`` so the
``author`` command can host it beside ``author record``. ``--record FILE`` records the
session (its pointer and keys as tool operations, the clip and viewport state each step);
``puppetphone replay FILE`` reopens the same clip from the recording and repeats the edits.
"""

from __future__ import annotations

import argparse
import base64
import hashlib
import sys
import tempfile
from pathlib import Path

import numpy as np

__all__ = ["configure_edit", "run_edit", "build_edit", "replay_edit", "edit_digest", "EditActivity", "EDIT_GAME"]

#: The name an edit session's recording gives as its game.
EDIT_GAME = "author-edit"
MAX_CHARACTER = 8 << 20  # bytes of a GLB a recording carries (its header holds at most 16 MB)


def configure_edit(parser: argparse.ArgumentParser) -> None:
    """Add the ``author edit`` arguments."""
    from puppetphone.argtypes import output_file, take_position
    from puppetphone.runargs import add_run_arguments

    parser.add_argument("clip", help="a .ppclip cycle, a .bvh/.gltf/.glb motion (opened as its loop), "
                                     "or a default clip name (walk, run, crouch_walk, idle…)")
    from puppetphone.motion_args import add_motion_options

    add_motion_options(parser)
    parser.add_argument("--retarget", action="store_true", help="a BVH/glTF motion: edit it on the puppet's skeleton")
    parser.add_argument("--start", metavar="T0", type=take_position, help="a take: extract the loop from here "
                        "(seconds, or a frame: 480f)")
    parser.add_argument("--end", metavar="T1", type=take_position, help="a take: ...up to here (excluded)")
    parser.add_argument("--items", metavar="JOINT", nargs="+", help="a take: extract the loop from these joints' "
                        "motion only (the legs of a dance whose arms vary); the others keep their mean pose")
    parser.add_argument("-o", "--output", type=Path, default=None, help="where Ctrl+S saves (.ppclip)")
    parser.add_argument("--export", type=Path, action="append", default=[],
                        help="also write the edited cycle here on exit (.ppclip, .bvh, .glb, .gltf); repeatable")  # fmt: skip
    parser.add_argument("--record", type=output_file, default=None,
                        help="record the session (pointer, keys, every step's state) to replay it later")
    add_run_arguments(parser)


def _motion_setup(path: Path, size: tuple[int, int], options: dict[str, object] | None) -> dict[str, object]:
    """A motion file opened as its loop, as the setup a recording keeps: the loop's ``.ppclip`` bytes.

    The live session is built from these same bytes (:func:`_reopen`), so a replay opens
    exactly the clip the session edited, whatever the file, its options or the extractor."""
    from authoring.motion_loop import open_loop
    from engine.clipfile import save_clip

    clip, note = open_loop(path, **(options or {}))  # type: ignore[arg-type]
    print(note, file=sys.stderr)
    with tempfile.TemporaryDirectory() as tmp:
        data = save_clip(clip, Path(tmp) / "clip.ppclip").read_bytes()
    return {"clip": str(path), "size": list(size), "name": path.stem + ".ppclip",
            "ppclip": base64.b64encode(data).decode(), "side": "", "character": _character_setup(path)}


def _character_setup(path: Path) -> str:
    """A GLB's bytes (base64) when it holds a skinned mesh to draw, so a replay draws it too; else ``""``."""
    from engine.io.gltf import GltfError
    from engine.io.gltf_mesh import read_skinned_meshes

    if path.suffix.lower() != ".glb":
        return ""
    try:
        meshes = read_skinned_meshes(path)
    except GltfError:
        return ""  # no skin or no mesh: the motion alone, drawn as the mannequin
    if meshes.ignored:
        print(f"{path.name}: not drawn: {', '.join(meshes.ignored)}", file=sys.stderr)
    size = path.stat().st_size
    if size > MAX_CHARACTER:
        print(f"{path.name}: the character ({size >> 20} MB) is over the {MAX_CHARACTER >> 20} MB a recording "
              f"carries: drawn live, a replay draws the mannequin", file=sys.stderr)
        return ""
    return base64.b64encode(path.read_bytes()).decode()


def _character(setup: dict[str, object], skeleton):  # type: ignore[no-untyped-def]
    """The skinned character of the set-up bound to the loop's skeleton, or None (said in one line)."""
    from engine.io.gltf import GltfError, read_gltf
    from engine.io.gltf_mesh import read_skinned_meshes
    from engine.skinning import SkinBinding

    if not setup.get("character"):
        return None
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "character.glb"
        path.write_bytes(base64.b64decode(str(setup["character"])))
        try:
            return SkinBinding.bind(read_gltf(path), read_skinned_meshes(path), skeleton)
        except (GltfError, ValueError) as exc:
            print(f"the character is drawn as the mannequin: {str(exc).replace(str(path), 'the file')}", file=sys.stderr)
            return None


def _open(spec: str, options: dict[str, object] | None = None):  # type: ignore[no-untyped-def]
    from authoring.mocurves import EditSession, load_session
    from engine.clips import default_clips
    from engine.io.motion_file import MOTION_SUFFIXES

    path = Path(spec)
    suffix = path.suffix.lower()
    if path.exists() and suffix in MOTION_SUFFIXES:
        setup = _motion_setup(path, (0, 0), options)
        return _reopen(setup), path.with_name(path.stem + "_edited.ppclip")
    if path.exists() and suffix != ".ppclip":
        raise ValueError(f"{path} is not a clip file: author edit opens a .ppclip cycle, a motion file "
                         f"({', '.join(MOTION_SUFFIXES)}) or a default clip ({', '.join(default_clips())})")
    if suffix == ".ppclip":
        return load_session(path), path.with_name(path.stem + "_edited.ppclip")
    clips = default_clips()
    if spec not in clips:
        raise ValueError(f"{spec!r} is neither a .ppclip file nor a default clip ({', '.join(clips)}) "
                         f"nor a motion file ({', '.join(MOTION_SUFFIXES)})")
    return EditSession(clips[spec]), Path(f"{spec}_edited.ppclip")


def _setup(spec: str, size: tuple[int, int]) -> dict[str, object]:
    """What a recording needs to reopen the same session: the clip's bytes (and side file), not its path."""
    from authoring.mocurves.storage import side_path

    path = Path(spec)
    setup: dict[str, object] = {"clip": spec, "size": list(size)}
    if path.suffix.lower() == ".ppclip":
        setup["name"] = path.name
        setup["ppclip"] = base64.b64encode(path.read_bytes()).decode()
        side = side_path(path)
        setup["side"] = base64.b64encode(side.read_bytes()).decode() if side.exists() else ""
    return setup


def _check_setup(setup: object) -> dict[str, object]:
    """A recorded edit set-up, every value checked; a clip without its bytes must be a default clip's name.

    A recording is self-contained: a path in it never makes a replay open a file (a clip
    on the replaying person's disk). ``ValueError`` in one line for anything else.
    """
    from engine.clips import default_clips

    if not isinstance(setup, dict):
        raise ValueError("the recorded edit set-up is not an object")
    size = setup.get("size", [1280, 720])
    if not (isinstance(size, list) and len(size) == 2
            and all(isinstance(v, int) and not isinstance(v, bool) and 0 <= v <= 16384 for v in size)):
        raise ValueError("the recorded window size is not two whole numbers in 0..16384")
    for key in ("clip", "name", "ppclip", "side", "character"):
        if not isinstance(setup.get(key, ""), str):
            raise ValueError(f"the recorded {key} is not text")
    if len(str(setup.get("character", ""))) > (MAX_CHARACTER * 4) // 3 + 4:
        raise ValueError(f"the recorded character is over {MAX_CHARACTER >> 20} MB")
    if not setup.get("ppclip") and setup.get("clip") not in default_clips():
        raise ValueError(f"the recording names the clip {str(setup.get('clip'))[:80]!r} without carrying it; "
                         f"a replay opens only a clip the recording holds or a default clip")
    return setup


def _reopen(setup: dict[str, object]):  # type: ignore[no-untyped-def]
    """The recorded session's clip, from the recording alone (never from a path it names)."""
    from authoring.mocurves import load_session
    from authoring.mocurves.storage import side_path

    setup = _check_setup(setup)
    if not setup.get("ppclip"):
        return _open(str(setup["clip"]))[0]
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / Path(str(setup.get("name", "clip.ppclip"))).name
        path.write_bytes(base64.b64decode(str(setup["ppclip"])))
        if setup.get("side"):
            side_path(path).write_bytes(base64.b64decode(str(setup["side"])))
        return load_session(path)


def edit_digest(edit) -> tuple[str, dict[str, bytes]]:  # type: ignore[no-untyped-def]
    """The edit scene's state in parts: the clip, the scale tracks, the viewport."""
    from engine.hashing import combine_parts

    clip = edit.session.clip
    parts = []
    for name, arrays in (("clip", (clip.root, clip.rotations)), ("scales", (edit.session.scales,))):
        h = hashlib.blake2b(name.encode(), digest_size=16)
        for a in arrays:
            h.update(np.ascontiguousarray(a, dtype=np.float64).tobytes())
        parts.append((name, h))
    cam = edit.camera
    h = hashlib.blake2b(b"scene", digest_size=16)
    h.update(np.array([edit.time, cam.yaw, cam.pitch, cam.distance, *np.asarray(cam.target, dtype=np.float64),
                       edit.session.tau, edit.session.sigma, edit.focus, *edit.size], dtype=np.float64).tobytes())
    h.update(f"{edit.item}|{edit.layer}|{edit.mode}|{edit.playing}|{edit.session.revision}".encode())
    parts.append(("scene", h))
    return combine_parts(parts)


class EditActivity:
    """The MoCurves scene as the runner's activity: the loop plays at the fixed 60 Hz step.

    The pointer, wheel and keys reach the scene as tool operations through the input hub
    (queued by :meth:`on_event`, applied at the next step), so a session records like a
    game and replays to the same clip: ``--record FILE``, ``puppetphone replay FILE``.
    A replay saves nothing; Ctrl+S there only checks that the state matches.
    """

    dt = 1.0 / 60.0

    def __init__(self, edit, session, output: Path | None, hub, *, recorder=None, check=None) -> None:  # type: ignore[no-untyped-def]
        self.edit, self.session, self.output, self.hub = edit, session, output, hub
        self.recorder, self.check = recorder, check
        self.camera = edit.camera
        self.frame = 0
        self._orbiting = False
        self._pending: list[object] | None = None  # the latest pointer move or summed orbit of this step

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
        """Translate one pygame event into a tool operation (Esc and P stay the runner's)."""
        import pygame

        try:
            mods = ev.mod if ev.type == pygame.KEYDOWN else pygame.key.get_mods()
        except pygame.error:  # no display initialised (a scripted session): no modifier held
            mods = 0
        shift = bool(mods & pygame.KMOD_SHIFT)
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
        elif ev.type == pygame.KEYDOWN and ev.key not in (pygame.K_ESCAPE, pygame.K_p):
            self._queue(["key", pygame.key.name(ev.key), bool(mods & pygame.KMOD_CTRL), shift])
        else:
            return False
        return True

    def _apply(self, op: tuple) -> None:
        from authoring.mocurves import save_session
        from puppetphone.saving import save_or_say

        edit, kind = self.edit, op[0]
        if kind == "press":
            edit.press(op[1], op[2], shift=bool(op[3]))
        elif kind == "move":
            edit.move(op[1], op[2])
        elif kind == "release":
            edit.release(op[1], op[2])
        elif kind == "orbit":
            edit.camera.orbit(-op[1] * 0.01, op[2] * 0.01)
        elif kind == "zoom":
            edit.camera.zoom(float(op[1]))
        elif kind == "size":
            edit.size = (int(op[1]), int(op[2]))
        elif kind == "key" and op[2] and op[1] == "s":
            if self.output is not None:
                edit.message = save_or_say(lambda path: save_session(self.session, path), self.output)
        elif kind == "key":
            edit.key(op[1], ctrl=bool(op[2]), shift=bool(op[3]))

    def step(self) -> None:
        self._flush()
        frame = self.hub.drain(self.frame)
        for op in frame.tool_operations():
            try:
                self._apply(op)
            except (IndexError, TypeError):
                raise ValueError(f"tool operation {list(op)} does not fit the edit scene") from None
        self.edit.step(self.dt)
        digest, parts = edit_digest(self.edit)
        if self.recorder is not None:
            self.recorder.write(frame, digest, parts)
        if self.check is not None:
            self.check.check(self.frame, digest, parts)
        self.frame += 1

    def draw(self, scene, alpha: float, size: tuple[int, int]) -> None:  # type: ignore[no-untyped-def]
        self.edit.draw(scene)


def build_edit(spec: str, size: tuple[int, int], output: Path | None, *, record: Path | None = None,  # type: ignore[no-untyped-def]
               options: dict[str, object] | None = None):
    """A live edit session of ``spec`` (optionally recorded); ``options`` open a motion file."""
    from authoring.edit_scene import EditScene
    from engine.io.motion_file import MOTION_SUFFIXES
    from input.hub import InputHub
    from input.recording import Recorder, RecordingHeader

    path = Path(spec)
    if path.exists() and path.suffix.lower() in MOTION_SUFFIXES:
        setup = _motion_setup(path, size, options)
        session, default_out = _reopen(setup), path.with_name(path.stem + "_edited.ppclip")
    else:
        session, default_out = _open(spec, options)
        setup = _setup(spec, size) if record is not None else {}
    recorder = None
    if record is not None:
        recorder = Recorder(record, RecordingHeader(game=EDIT_GAME, seed=0, dt=EditActivity.dt, sources=["mouse"],
                                                    setup=setup))
    scene = EditScene(session, size, character=_character(setup, session.clip.skeleton))
    return EditActivity(scene, session, output or default_out, InputHub(), recorder=recorder)


def replay_edit(recording, verify: bool = True):  # type: ignore[no-untyped-def]
    """The recorded edit session, rebuilt from the recording alone, checking every step."""
    from authoring.edit_scene import EditScene
    from input.hub import InputHub
    from input.replay import HashCheck, ReplaySource

    setup = _check_setup(recording.header.setup)
    session = _reopen(setup)
    edit = EditScene(session, tuple(setup.get("size", (1280, 720))), character=_character(setup, session.clip.skeleton))
    return EditActivity(edit, session, None, InputHub(replay=ReplaySource(recording)),
                        check=HashCheck(recording) if verify else None)


def _motion_options(args: argparse.Namespace) -> dict[str, object]:
    from engine.io.motion_file import MOTION_SUFFIXES
    from puppetphone.motion_args import motion_options

    given = [f"--{k}" for k in ("animation", "units", "height", "joint_map", "retarget", "start", "end", "items")
             if getattr(args, k, None) is not None and getattr(args, k, None) is not False]
    if given and Path(args.clip).suffix.lower() not in MOTION_SUFFIXES:
        raise ValueError(f"{', '.join(g.replace('_', '-') for g in given)} only apply to a BVH/glTF/GLB file")
    return {**motion_options(args), "retarget": bool(getattr(args, "retarget", False)),
            "start": getattr(args, "start", None), "end": getattr(args, "end", None),
            "items": getattr(args, "items", None)}


def run_edit(args: argparse.Namespace) -> int:
    """Open the clip, run the scene until the window closes (or ``--frames``), save/export."""
    from authoring.mocurves import export_clip
    from authoring.mocurves.storage import EXPORT_SUFFIXES
    from engine.render.window import NoDisplayError
    from engine.runner import Runner
    from puppetphone.runargs import run_options

    for path in args.export:
        if path.suffix.lower() not in EXPORT_SUFFIXES:
            print(f"error: cannot export {path}: use one of {', '.join(EXPORT_SUFFIXES)}", file=sys.stderr)
            return 2
    runner = Runner(run_options(args, "PuppetPhone — MoCurves"))
    try:
        runner.open()
    except NoDisplayError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    try:
        activity = build_edit(args.clip, runner.size, args.output, record=args.record, options=_motion_options(args))
    except (ValueError, OSError) as exc:
        runner.close()
        from puppetphone.motion_args import about

        print(f"cannot open {about(args.clip, exc)}", file=sys.stderr)
        return 2
    runner.push_handlers(activity)
    try:
        result = runner.run(activity)
        if result.screenshot is not None:
            print(f"screenshot: {result.screenshot}")
        for path in args.export:
            export_clip(activity.session.clip, path)
            print(f"exported {path}")
    finally:
        runner.close()
        if activity.recorder is not None:
            activity.recorder.close()
            print(f"recorded {activity.recorder.frames} steps to {activity.recorder.path}", file=sys.stderr)
    return 0
