"""The ``author edit`` tool: MoCurves over a playing cycle, as a session's simulation (beside :mod:`authoring.edit_scene`).

The tool opens a ``.ppclip`` cycle (its ``.mocurves.json`` side file too), a BVH/glTF/GLB
motion opened as its loop (:mod:`authoring.motion_loop`) or a default clip. A recording
keeps the clip's bytes (never its path), so a replay reopens exactly the clip that was
edited and repeats the operations; Ctrl+S saves to the output (a replay saves nothing).
"""

from __future__ import annotations

import base64
import hashlib
import sys
import tempfile
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from authoring.bindings import orbit_camera
from authoring.operations import Key, Move, Operation, Orbit, Press, Release, Resize, Zoom
from authoring.session import Ending, Opened, ToolKind, ToolSimulation
from engine.camera import Camera
from engine.render.scene import RenderScene
from input.sample import InputFrame

if TYPE_CHECKING:
    from authoring.edit_scene import EditScene
    from authoring.mocurves import EditSession
    from engine.skeleton import Skeleton
    from engine.skinning import SkinBinding

__all__ = ["EDIT_GAME", "TOOL", "EditTool", "edit_digest", "open_edit", "reopen_edit"]

#: The name an edit session's recording gives as its game.
EDIT_GAME = "author-edit"
MAX_CHARACTER = 8 << 20  # bytes of a GLB a recording carries (its header holds at most 16 MB)


def _motion_setup(path: Path, size: tuple[int, int], options: Mapping[str, Any] | None) -> dict[str, object]:
    """A motion file opened as its loop, as the setup a recording keeps: the loop's ``.ppclip`` bytes.

    The live session is built from these same bytes (:func:`_reopen`), so a replay opens
    exactly the clip the session edited, whatever the file, its options or the extractor."""
    from authoring.motion_loop import open_loop
    from engine.clipfile import save_clip

    clip, note = open_loop(path, **(options or {}))
    print(note, file=sys.stderr)
    with tempfile.TemporaryDirectory() as tmp:
        data = save_clip(clip, Path(tmp) / "clip.ppclip").read_bytes()
    return {
        "clip": str(path),
        "size": list(size),
        "name": path.stem + ".ppclip",
        "ppclip": base64.b64encode(data).decode(),
        "side": "",
        "character": _character_setup(path),
    }


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
        print(
            f"{path.name}: the character ({size >> 20} MB) is over the {MAX_CHARACTER >> 20} MB a recording "
            f"carries: drawn live, a replay draws the mannequin",
            file=sys.stderr,
        )
        return ""
    return base64.b64encode(path.read_bytes()).decode()


def _character(setup: dict[str, object], skeleton: Skeleton) -> SkinBinding | None:
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
            print(
                f"the character is drawn as the mannequin: {str(exc).replace(str(path), 'the file')}", file=sys.stderr
            )
            return None


def _open(spec: str, options: Mapping[str, Any] | None = None) -> tuple[EditSession, Path]:
    from authoring.mocurves import EditSession, load_session
    from engine.clips import default_clips
    from engine.io.motion_file import MOTION_SUFFIXES

    path = Path(spec)
    suffix = path.suffix.lower()
    if path.exists() and suffix in MOTION_SUFFIXES:
        setup = _motion_setup(path, (0, 0), options)
        return _reopen(setup), path.with_name(path.stem + "_edited.ppclip")
    if path.exists() and suffix != ".ppclip":
        raise ValueError(
            f"{path} is not a clip file: author edit opens a .ppclip cycle, a motion file "
            f"({', '.join(MOTION_SUFFIXES)}) or a default clip ({', '.join(default_clips())})"
        )
    if suffix == ".ppclip":
        return load_session(path), path.with_name(path.stem + "_edited.ppclip")
    clips = default_clips()
    if spec not in clips:
        raise ValueError(
            f"{spec!r} is neither a .ppclip file nor a default clip ({', '.join(clips)}) "
            f"nor a motion file ({', '.join(MOTION_SUFFIXES)})"
        )
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
    if not (
        isinstance(size, list)
        and len(size) == 2
        and all(isinstance(v, int) and not isinstance(v, bool) and 0 <= v <= 16384 for v in size)
    ):
        raise ValueError("the recorded window size is not two whole numbers in 0..16384")
    for key in ("clip", "name", "ppclip", "side", "character"):
        if not isinstance(setup.get(key, ""), str):
            raise ValueError(f"the recorded {key} is not text")
    if len(str(setup.get("character", ""))) > (MAX_CHARACTER * 4) // 3 + 4:
        raise ValueError(f"the recorded character is over {MAX_CHARACTER >> 20} MB")
    if not setup.get("ppclip") and setup.get("clip") not in default_clips():
        raise ValueError(
            f"the recording names the clip {str(setup.get('clip'))[:80]!r} without carrying it; "
            f"a replay opens only a clip the recording holds or a default clip"
        )
    return setup


def _reopen(setup: dict[str, object]) -> EditSession:
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


def edit_digest(edit: EditScene) -> tuple[str, dict[str, bytes]]:
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
    h.update(
        np.array(
            [
                edit.time,
                cam.yaw,
                cam.pitch,
                cam.distance,
                *np.asarray(cam.target, dtype=np.float64),
                edit.session.tau,
                edit.session.sigma,
                edit.focus,
                *edit.size,
            ],
            dtype=np.float64,
        ).tobytes()
    )
    h.update(f"{edit.item}|{edit.layer}|{edit.mode}|{edit.playing}|{edit.session.revision}".encode())
    parts.append(("scene", h))
    return combine_parts(parts)


class EditTool(ToolSimulation):
    """The MoCurves scene as a session's simulation: the loop plays at the fixed 60 Hz step."""

    def __init__(self, edit: Any, session: Any, output: Path | None, exports: list[Path] | None = None) -> None:
        self.edit, self.session, self.output = edit, session, output
        self.exports = list(exports or [])

    @property
    def camera(self) -> Camera:
        """The scene's orbit camera."""
        return self.edit.camera

    def apply(self, op: Operation) -> None:
        """Pointer gestures, camera, window size and keys (Ctrl+S saves)."""
        from authoring.mocurves import save_session
        from authoring.saving import save_or_say

        edit = self.edit
        if isinstance(op, Press):
            edit.press(op.x, op.y, shift=op.shift)
        elif isinstance(op, Move):
            edit.move(op.x, op.y)
        elif isinstance(op, Release) and op.x is not None and op.y is not None:
            edit.release(op.x, op.y)
        elif isinstance(op, Orbit):
            orbit_camera(edit.camera, op)
        elif isinstance(op, Zoom):
            edit.camera.zoom(op.factor)
        elif isinstance(op, Resize):
            edit.size = (op.width, op.height)
        elif isinstance(op, Key) and op.ctrl and op.name == "s":
            if self.output is not None:
                edit.message = save_or_say(lambda path: save_session(self.session, path), self.output)
        elif isinstance(op, Key):
            edit.key(op.name, ctrl=op.ctrl, shift=op.shift)

    def advance(self, frame: InputFrame) -> None:
        """The loop plays one step."""
        self.edit.step(self.dt)

    def digest(self) -> tuple[str, dict[str, bytes]]:
        """:func:`edit_digest`."""
        return edit_digest(self.edit)

    def draw(self, scene: RenderScene, alpha: float, size: tuple[int, int]) -> None:
        """The edit scene."""
        self.edit.draw(scene)

    def conclude(self) -> Ending:
        """Write the exports (a live session's end)."""
        from authoring.mocurves import export_clip

        lines = []
        for path in self.exports:
            export_clip(self.session.clip, path)
            lines.append(f"exported {path}")
        return Ending(lines)


def open_edit(options: Mapping[str, Any], size: tuple[int, int]) -> Opened:
    """A live edit session: ``clip`` (spec), ``output``, ``export`` (paths) and ``motion`` (motion-file options)."""
    from authoring.edit_scene import EditScene
    from authoring.mocurves.storage import EXPORT_SUFFIXES
    from engine.io.motion_file import MOTION_SUFFIXES

    exports = [Path(p) for p in options.get("export") or []]
    for path in exports:
        if path.suffix.lower() not in EXPORT_SUFFIXES:
            raise ValueError(f"cannot export {path}: use one of {', '.join(EXPORT_SUFFIXES)}")
    spec, motion = str(options["clip"]), options.get("motion")
    path = Path(spec)
    if path.exists() and path.suffix.lower() in MOTION_SUFFIXES:
        setup = _motion_setup(path, size, motion)
        session, default_out = _reopen(setup), path.with_name(path.stem + "_edited.ppclip")
    else:
        session, default_out = _open(spec, motion)
        setup = _setup(spec, size)
    scene = EditScene(session, size, character=_character(setup, session.clip.skeleton))
    tool = EditTool(scene, session, options.get("output") or default_out, exports)
    return Opened(tool, setup, conclude=tool.conclude)


def reopen_edit(setup: object) -> EditTool:
    """The recorded edit session, rebuilt from the recording's set-up alone (it saves nothing)."""
    from authoring.edit_scene import EditScene

    checked = _check_setup(setup)
    session = _reopen(checked)
    size = checked.get("size", [1280, 720])
    assert isinstance(size, list)  # checked: two whole numbers
    edit = EditScene(session, (int(size[0]), int(size[1])), character=_character(checked, session.clip.skeleton))
    return EditTool(edit, session, None)


TOOL = ToolKind(EDIT_GAME, "PuppetPhone — MoCurves", open_edit, reopen_edit)
