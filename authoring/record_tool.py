"""The ``author record`` tool: act a motion cycle out, as a session's simulation (beside :mod:`authoring.record_scene`).

Each step feeds the performer's value to the scene: the scripted loops (``--script
loops``), a device's pose from the input hub (its orientation and tracked position
relative to where they were when the take began) or the mouse (a left-drag from the press
point: for a rotation the drag turns the joint, for a translation the cursor is the
position). The session steps at the fixed 60 Hz whatever the frame rate, so the countdown
and the performer's tempo are real time; a recording keeps the set-up (the base clip's
bytes included) and replays the take.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from authoring.bindings import orbit_camera
from authoring.operations import Key, Move, Operation, Orbit, Press, Release, Resize, Zoom
from authoring.session import Ending, Opened, ToolKind, ToolSimulation
from engine.camera import Camera
from engine.render.scene import RenderScene
from input.sample import InputFrame

if TYPE_CHECKING:
    import numpy as np
    from numpy.typing import NDArray

    from authoring.record_scene import RecordScene

__all__ = ["RECORD_GAME", "TOOL", "RecordTool", "open_record", "record_digest", "reopen_record"]

#: The name a take's recording gives as its game.
RECORD_GAME = "author-record"


def _scripted(
    step: int, fps: float, rng_phase: list[float], drive: str, centre: NDArray[np.float64], rest: NDArray[np.float64]
) -> NDArray[np.float64]:
    """The scripted performer: loops of 1.2 s ± 15 % with a tremor, as a value for the scene."""
    import numpy as np

    from authoring.record_scene import drag_rotation

    # Tempo wobbles slowly between 0.87 and 1.15 of nominal: the phase integrates it.
    tempo = 1.0 + 0.15 * np.sin(2 * np.pi * step / fps / 5.3)
    rng_phase[0] += tempo / (1.2 * fps)
    p = 2 * np.pi * rng_phase[0]
    tremor = 0.01 * np.sin(step * 1.7)
    if drive == "scale":
        return rest * (1.0 + 0.25 * np.sin(p) ** 2 + tremor)
    from engine import quat

    position = centre + np.array([0.15 * np.sin(p), 0.08 * np.sin(2 * p) + tremor, 0.0])
    if drive == "translation":
        return position
    q = quat.mul(rest[-4:], drag_rotation(260 * np.sin(p) + 40 * tremor, 160 * np.sin(2 * p + 0.5), 720))
    return np.concatenate([position, q]) if drive == "pose" else q


def record_digest(scene: RecordScene) -> tuple[str, dict[str, bytes]]:
    """The record scene's state in parts: the stacked clip, the candidate loop, the take, the rest."""
    import hashlib

    import numpy as np

    from engine.hashing import combine_parts, feed

    parts = []
    for name, clip in (("clip", scene.clip), ("candidate", scene.candidate)):
        h = hashlib.blake2b(name.encode(), digest_size=16)
        if clip is not None:
            h.update(np.ascontiguousarray(clip.root).tobytes() + np.ascontiguousarray(clip.rotations).tobytes())
        parts.append((name, h))
    h = hashlib.blake2b(b"take", digest_size=16)
    take = scene.take
    if take is not None and take.values:
        h.update(
            np.asarray(take.times, dtype=np.float64).tobytes() + np.asarray(take.values, dtype=np.float64).tobytes()
        )
    parts.append(("take", h))
    h = hashlib.blake2b(b"scene", digest_size=16)
    feed(
        h,
        [
            scene.phase,
            scene.time,
            scene.timer,
            scene.rng.bit_generator.state,
            None if scene.value is None else np.asarray(scene.value, dtype=np.float64),
        ],
    )
    cam = scene.camera
    h.update(np.array([cam.yaw, cam.pitch, cam.distance], dtype=np.float64).tobytes())
    parts.append(("scene", h))
    return combine_parts(parts)


class RecordTool(ToolSimulation):
    """The record scene as a session's simulation (see the module docstring)."""

    def __init__(
        self, scene: Any, *, script: str | None = None, output: Path | None = None, size: tuple[int, int] = (1280, 720)
    ) -> None:
        self.scene, self.script, self.output = scene, script, output
        self.size = (int(size[0]), int(size[1]))
        self.frame, self.previewing = 0, 0
        self.press: tuple[float, float, Any] | None = None
        self.pointer: tuple[float, float] | None = None
        self.phase_acc = [0.0]
        self.reference: Any = None
        self.reference_position: Any = None
        self.rest = scene.rest_value()
        self.saved: list[str] = []
        if script:
            scene.start()

    @property
    def camera(self) -> Camera:
        """The scene's orbit camera."""
        return self.scene.camera

    def _save(self, message: str) -> bool:
        """Save the accepted cycle; whether it was written (a failure is shown, the take stays open)."""
        from authoring.saving import save_or_say
        from engine.clipfile import save_clip

        if self.output is None or self.scene.clip is None:
            return False
        clip, curve = self.scene.clip, self.scene.root_curve
        said = save_or_say(lambda path: save_clip(clip, path, root_curve=curve), self.output)
        saved = said.startswith("saved")
        self.scene.message = message.format(output=self.output) if saved else said
        return saved

    def apply(self, op: Operation) -> None:
        """A press picks a joint (while ready) or starts a drag; keys drive the take; Ctrl+S saves."""
        scene = self.scene
        if isinstance(op, Press) and scene.choose(op.x, op.y, self.size):
            self.rest = scene.rest_value()  # a click on the figure while ready picks the joint to drive
        elif isinstance(op, Press):
            self.press, self.rest = (op.x, op.y, scene.item_position()), scene.rest_value()
            self.pointer = (op.x, op.y)
        elif isinstance(op, Move) and self.press is not None:
            self.pointer = (op.x, op.y)
        elif isinstance(op, Release):
            self.press = self.pointer = None
        elif isinstance(op, Orbit):
            orbit_camera(scene.camera, op)
        elif isinstance(op, Zoom):
            scene.camera.zoom(op.factor)
        elif isinstance(op, Resize):
            self.size = (op.width, op.height)
        elif isinstance(op, Key) and op.ctrl and op.name == "s":
            self._save("saved {output}")
        elif isinstance(op, Key) and op.name in ("return", "enter"):
            if scene.accept() is not None:
                self._save("layer accepted and saved to {output}; R records another")
        elif isinstance(op, Key):
            scene.key(op.name)

    def _value(self, frame: InputFrame) -> Any:
        import numpy as np

        from authoring.record_scene import drag_rotation, mouse_point
        from engine import quat

        scene = self.scene
        if self.script:
            return _scripted(self.frame, 1.0 / self.dt, self.phase_acc, scene.drive, scene.item_position(), self.rest)
        sample = frame.latest()
        if sample is not None and sample.source != "mouse":
            return self._device_value(sample)
        if self.press is None or self.pointer is None:
            return None
        px, py = self.pointer
        if scene.drive == "rotation":
            return quat.mul(self.rest, drag_rotation(px - self.press[0], py - self.press[1], self.size[1]))
        if scene.drive == "scale":  # drag up to grow, down to shrink: a screen height is a factor e^2
            return self.rest * np.exp(2.0 * (self.press[1] - py) / self.size[1])
        point = mouse_point(scene.camera, px, py, self.size, self.press[2])
        return point if scene.drive == "translation" else np.concatenate([point, self.rest[-4:]])

    def _device_value(self, sample: Any) -> Any:
        """A device's value: its orientation and tracked position relative to where they were when the take began."""
        import numpy as np

        from engine import quat

        scene = self.scene
        if scene.drive == "scale":
            return None  # a device's pose holds no scale: a scale is performed with the mouse
        if scene.phase != "recording" or self.reference is None:
            self.reference, self.rest = sample.orientation, scene.rest_value()
            self.reference_position = None if sample.position is None else np.array(sample.position, dtype=np.float64)
        if scene.drive in ("translation", "pose") and (sample.position is None or self.reference_position is None):
            return None  # an orientation-only device (an IMU, a gamepad) cannot perform a position
        rotation = quat.mul(quat.mul(sample.orientation, quat.conjugate(self.reference)), self.rest[-4:])
        if scene.drive == "rotation":
            return rotation
        position = self.rest[:3] + (np.asarray(sample.position, dtype=np.float64) - self.reference_position)
        return position if scene.drive == "translation" else np.concatenate([position, rotation])

    def advance(self, frame: InputFrame) -> None:
        """Feed the performer's value and step the scene; the scripted performer accepts after 2 s of preview."""
        scene = self.scene
        scene.feed(self._value(frame))
        scene.step(self.dt)
        self.previewing = self.previewing + 1 if scene.phase == "preview" else 0
        accepted = self.script and self.previewing == int(2 / self.dt) and scene.accept() is not None
        if accepted and self._save("saved {output}"):
            self.saved.append(f"saved {self.output}")
        self.frame += 1

    def digest(self) -> tuple[str, dict[str, bytes]]:
        """:func:`record_digest`."""
        return record_digest(self.scene)

    def draw(self, scene: RenderScene, alpha: float, size: tuple[int, int]) -> None:
        """The record scene."""
        self.scene.draw(scene)

    def conclude(self) -> Ending:
        """What was saved and the scene's last message."""
        return Ending([*self.saved, self.scene.message])


def open_record(options: Mapping[str, Any], size: tuple[int, int]) -> Opened:
    """A live take: ``item``, ``drive``, ``base``, ``output``, ``countdown``, ``seconds``, ``seed``, ``script``."""
    setup = _record_setup(options, size)
    output = options.get("output")
    tool = RecordTool(
        _record_scene(setup),
        script=_script_of(setup),
        output=Path(output) if output else None,
        size=size,
    )
    return Opened(tool, setup, conclude=tool.conclude)


def reopen_record(setup: object) -> RecordTool:
    """The recorded take, rebuilt from its set-up alone (saving nothing)."""
    checked = _check_record_setup(setup)
    size = checked.get("size", [1280, 720])
    assert isinstance(size, list)  # checked: two whole numbers
    return RecordTool(_record_scene(checked), script=_script_of(checked), size=(int(size[0]), int(size[1])))


def _script_of(setup: Mapping[str, object]) -> str | None:
    """The set-up's scripted performer: ``"loops"`` or ``None`` (a command-line choice, or checked when reopened)."""
    script = setup.get("script")
    return script if isinstance(script, str) else None


def _record_setup(options: Mapping[str, Any], size: tuple[int, int]) -> dict[str, object]:
    """Everything the take depends on, the base clip's bytes (and a ``--character``'s) included."""
    import base64

    from engine.character.setup import character_setup

    base, character = options.get("base"), options.get("character")
    return {
        "item": options.get("item", "r_upper_arm"),
        "drive": options.get("drive", "rotation"),
        "countdown": float(options.get("countdown", 3.0)),
        "seconds": float(options.get("seconds", 8.0)),
        "seed": int(options.get("seed", 0)),
        "script": options.get("script"),
        "size": list(size),
        "base": base64.b64encode(Path(base).read_bytes()).decode() if base is not None else "",
        **({"character": character_setup(character)} if character else {}),
    }


def _check_record_setup(setup: object) -> dict[str, object]:
    """A recorded take's set-up, every value type- and range-checked (``ValueError`` in one line)."""
    import math

    def number(key: str, lo: float, hi: float) -> None:
        v = checked.get(key)
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or not lo <= v <= hi:
            raise ValueError(f"the recorded {key} {repr(v)[:30]} is not a number in [{lo:g}, {hi:g}]")

    if not isinstance(setup, dict):
        raise ValueError("the recorded take's set-up is not an object")
    checked: dict[str, object] = setup
    if not isinstance(setup.get("item"), str) or not isinstance(setup.get("base", ""), str):
        raise ValueError("the recorded item and base must be text")
    if setup.get("drive") not in ("rotation", "translation", "pose", "scale"):
        raise ValueError(f"the recorded drive {repr(setup.get('drive'))[:30]} is not one the scene knows")
    if setup.get("script") not in (None, "loops"):
        raise ValueError(f"the recorded script {repr(setup.get('script'))[:30]} is not one the scene knows")
    number("countdown", 0.0, 600.0)
    number("seconds", 0.1, 3600.0)
    seed, size = setup.get("seed"), setup.get("size", [1280, 720])
    if not isinstance(seed, int) or isinstance(seed, bool) or not 0 <= seed < 2**63:
        raise ValueError("the recorded seed is not a whole number in 0..2**63-1")
    if not (
        isinstance(size, list)
        and len(size) == 2
        and all(isinstance(v, int) and not isinstance(v, bool) and 0 <= v <= 16384 for v in size)
    ):
        raise ValueError("the recorded window size is not two whole numbers in 0..16384")
    return setup


def _record_scene(setup: dict[str, Any]) -> Any:
    """The record scene of a checked set-up (its base clip decoded from the bytes it carries)."""
    import base64

    import numpy as np

    from authoring.record_scene import RecordScene
    from engine.clipfile import load_clip_curve
    from engine.humanoid import humanoid_skeleton

    base, curve = None, None
    if setup.get("base"):
        import tempfile

        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "base.ppclip"
            path.write_bytes(base64.b64decode(str(setup["base"])))
            base, curve = load_clip_curve(path)
    skeleton = base.skeleton if base is not None else humanoid_skeleton()
    from engine.character.setup import decode

    character = decode(setup["character"]) if setup.get("character") is not None else None
    return RecordScene(
        skeleton,
        str(setup["item"]),
        str(setup["drive"]),
        base,
        float(setup["countdown"]),
        float(setup["seconds"]),
        np.random.default_rng(int(setup["seed"])),
        root_curve=curve,
        character=character,
    )


TOOL = ToolKind(RECORD_GAME, "PuppetPhone — record a cycle", open_record, reopen_record)
