"""``puppetphone author record|edit|curves|flow``: the authoring scenes.

``author record`` acts a motion cycle out (:mod:`authoring.record_scene`)::

    puppetphone author record --item r_lower_arm --drive rotation [--source mouse|osc|hid|serial]
                              [--base CYCLE.ppclip] [-o OUT.ppclip] [--countdown 3] [--seconds 8]
                              [--headless --frames N --screenshot PNG --script loops]

Mouse: hold the left button and move in loops — for a rotation the drag from the press
point turns the joint, for a translation (the root, or a hand or foot reached by IK) the
cursor is the position. A phone, HID or serial device drives a rotation with its
orientation (relative to where it pointed when the take began), a translation with its
tracked position (relative to where it was then), and a 6-DoF device (a tracked phone,
a SpaceMouse) drives ``--drive pose``: position and rotation together in one take. Keys: R record, Space stop, Enter accept, Backspace retry,
Ctrl+S save; right-drag orbits. Every accepted layer is saved to ``-o`` at once.

``--script loops`` replaces the hand with a scripted performer (loops of ±15 % tempo
jitter, a little tremor): a demo, and what the headless test runs.

``author edit`` is the MoCurves scene (``puppetphone.cmd_author_edit``); ``author flow``
bends a scene with Flow Curves (``puppetphone.cmd_author_flow``).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

__all__ = ["configure", "run", "RecordActivity", "replay_record", "record_digest", "RECORD_GAME"]


def configure(parser: argparse.ArgumentParser) -> None:
    """Add ``record``, ``flow`` and ``edit`` sub-commands."""
    from puppetphone.argtypes import output_file
    from puppetphone.runargs import add_run_arguments

    sub = parser.add_subparsers(dest="scene", metavar="SCENE")
    record_help = "act a cycle out with the mouse or a device; layers stack into a clip"
    rec = sub.add_parser("record", help=record_help, description=record_help)
    rec.set_defaults(_parser=rec)
    rec.add_argument("--item", default="r_upper_arm", help="joint to drive (default r_upper_arm)")
    rec.add_argument("--drive", default="rotation", choices=("rotation", "translation", "pose", "scale"),
                     help="what to drive: a joint's rotation, the root's or a hand's/foot's translation (IK), "
                          "or its pose (translation and rotation in one take, from a 6-DoF device)")
    rec.add_argument("--base", type=Path, default=None, help="a looping .ppclip whose layers play back while performing")
    rec.add_argument("-o", "--output", type=Path, default=Path("performed_cycle.ppclip"), help="where accepted cycles are saved")
    rec.add_argument("--countdown", type=float, default=3.0, help="seconds of countdown (default 3)")
    rec.add_argument("--seconds", type=float, default=8.0, help="length of a take (default 8)")
    rec.add_argument("--script", choices=("loops",), default=None, help="a scripted performer instead of a hand")
    add_run_arguments(rec)
    rec.add_argument("--seed", type=int, default=0, help="seed of the extractor's probe points")
    rec.add_argument("--record", type=output_file, default=None,
                     help="record the take (pointer, keys or device, every step's state) to replay it later")
    from input.factory import add_source_arguments

    add_source_arguments(rec)
    from puppetphone.cmd_author_flow import configure_flow

    flow_help = "bend a scene's flow with sketched strokes and centre-points (Flow Curves)"
    flow = sub.add_parser("flow", help=flow_help, description=flow_help)
    flow.set_defaults(_parser=flow)
    configure_flow(flow)
    try:
        from puppetphone.cmd_author_edit import configure_edit
    except ModuleNotFoundError:  # the MoCurves scene is optional
        return
    edit_help = "refine a cycle with MoCurves while it plays"
    edit = sub.add_parser("edit", help=edit_help, description=edit_help)
    edit.set_defaults(_parser=edit)
    configure_edit(edit)
    from puppetphone.cmd_author_curves import configure_curves

    curves_help = "author a keyframed clip: pose its keys, shape its motion curves and their timing (thesis ch. 4)"
    curves = sub.add_parser("curves", help=curves_help, description=curves_help)
    curves.set_defaults(_parser=curves)
    configure_curves(curves)


def run(args: argparse.Namespace) -> int:
    """Dispatch to the chosen scene."""
    if args.scene == "edit":
        from puppetphone.cmd_author_edit import run_edit

        return run_edit(args)
    if args.scene == "flow":
        from puppetphone.cmd_author_flow import run_flow

        return run_flow(args)
    if args.scene == "curves":
        from puppetphone.cmd_author_curves import run_curves

        return run_curves(args)
    if args.scene != "record":
        print("choose a scene: puppetphone author record|edit|curves|flow", file=sys.stderr)
        return 2
    return _record(args)


def _scripted(step: int, fps: float, rng_phase: list[float], drive: str, centre, rest):  # type: ignore[no-untyped-def]
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


RECORD_GAME = "author-record"


def record_digest(scene) -> tuple[str, dict[str, bytes]]:  # type: ignore[no-untyped-def]
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
        h.update(np.asarray(take.times, dtype=np.float64).tobytes() + np.asarray(take.values, dtype=np.float64).tobytes())
    parts.append(("take", h))
    h = hashlib.blake2b(b"scene", digest_size=16)
    feed(h, [scene.phase, scene.time, scene.timer, scene.rng.bit_generator.state,
             None if scene.value is None else np.asarray(scene.value, dtype=np.float64)])
    cam = scene.camera
    h.update(np.array([cam.yaw, cam.pitch, cam.distance], dtype=np.float64).tobytes())
    parts.append(("scene", h))
    return combine_parts(parts)


class RecordActivity:
    """The record scene as the runner's activity: one step feeds the performer's value.

    The performer is the scripted loops, a device (its orientation relative to where it
    pointed when the take began) or the mouse (a drag from the press point); the runner
    calls :meth:`step` at the fixed 60 Hz whatever the frame rate, so the countdown and
    the performer's tempo are real time. The pointer and keys reach the scene as tool
    operations through the hub (the pointer sampled once a step while pressed), so a take
    records (``--record FILE``) and replays (``puppetphone replay FILE``) like a game.
    """

    dt = 1.0 / 60.0

    def __init__(self, scene, hub, *, script: str | None = None, output: Path | None = None, size=(1280, 720),
                 recorder=None, check=None) -> None:
        self.scene, self.hub, self.script, self.output = scene, hub, script, output
        self.recorder, self.check = recorder, check
        self.camera = scene.camera
        self.size = tuple(size)
        self.frame, self.previewing = 0, 0
        self.pressed = False
        self.press: tuple[float, float, object] | None = None
        self.phase_acc = [0.0]
        self.reference = None
        self.reference_position = None
        self.rest = scene.rest_value()
        if script:
            scene.start()

    def finished(self) -> bool:
        if self.check is not None and not self.check.ok:
            return True
        return self.hub.replay is not None and self.frame > self.hub.replay.last_frame

    def on_event(self, ev, runner) -> bool:  # type: ignore[no-untyped-def]
        """Pointer, wheel and keys become tool operations (Esc and P stay the runner's)."""
        import pygame

        if ev.type == pygame.MOUSEBUTTONDOWN and ev.button == 1:
            self.pressed = True
            self.hub.tool("press", ev.pos[0], ev.pos[1])
        elif ev.type == pygame.MOUSEBUTTONUP and ev.button == 1:
            self.pressed = False
            self.hub.tool("release")
        elif ev.type == pygame.MOUSEMOTION and ev.buttons[2]:
            self.hub.tool("orbit", ev.rel[0], ev.rel[1])
        elif ev.type == pygame.MOUSEWHEEL:
            self.hub.tool("zoom", 0.9 if ev.y > 0 else 1.1)
        elif ev.type == pygame.KEYDOWN and ev.key not in (pygame.K_ESCAPE, pygame.K_p):
            self.hub.tool("key", pygame.key.name(ev.key), bool(ev.mod & pygame.KMOD_CTRL))
        else:
            return False
        return True

    def _save(self, message: str) -> bool:
        """Save the accepted cycle; whether it was written (a failure is shown, the take stays open)."""
        from engine.clipfile import save_clip
        from puppetphone.saving import save_or_say

        if self.output is None or self.scene.clip is None:
            return False
        clip, curve = self.scene.clip, self.scene.root_curve
        said = save_or_say(lambda path: save_clip(clip, path, root_curve=curve), self.output)
        saved = said.startswith("saved")
        self.scene.message = message.format(output=self.output) if saved else said
        return saved

    def _apply(self, op: tuple) -> object:
        """One tool operation; returns a pointer position when the operation is one."""
        scene, kind = self.scene, op[0]
        if kind == "press" and scene.choose(float(op[1]), float(op[2]), self.size):
            self.rest = scene.rest_value()  # a click on the figure while ready picks the joint to drive
        elif kind == "press":
            self.press, self.rest = (float(op[1]), float(op[2]), scene.item_position()), scene.rest_value()
        elif kind == "release":
            self.press = None
        elif kind == "pointer":
            return float(op[1]), float(op[2])
        elif kind == "orbit":
            scene.camera.orbit(-op[1] * 0.01, op[2] * 0.01)
        elif kind == "zoom":
            scene.camera.zoom(float(op[1]))
        elif kind == "key" and op[2] and op[1] == "s":
            self._save("saved {output}")
        elif kind == "key" and op[1] in ("return", "enter"):
            if scene.accept() is not None:
                self._save("layer accepted and saved to {output}; R records another")
        elif kind == "key":
            scene.key(op[1])
        return None

    def _value(self, frame, pointer):  # type: ignore[no-untyped-def]
        import numpy as np

        from authoring.record_scene import drag_rotation, mouse_point
        from engine import quat

        scene = self.scene
        if self.script:
            return _scripted(self.frame, 1.0 / self.dt, self.phase_acc, scene.drive, scene.item_position(), self.rest)
        sample = frame.latest()
        if sample is not None and sample.source != "mouse":
            return self._device_value(sample)
        if self.press is None or pointer is None:
            return None
        px, py = pointer
        if scene.drive == "rotation":
            return quat.mul(self.rest, drag_rotation(px - self.press[0], py - self.press[1], self.size[1]))
        if scene.drive == "scale":  # drag up to grow, down to shrink: a screen height is a factor e^2
            return self.rest * np.exp(2.0 * (self.press[1] - py) / self.size[1])
        point = mouse_point(scene.camera, px, py, self.size, self.press[2])
        return point if scene.drive == "translation" else np.concatenate([point, self.rest[-4:]])

    def _device_value(self, sample):  # type: ignore[no-untyped-def]
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

    def step(self) -> None:
        if self.pressed and self.hub.replay is None:
            import pygame

            self.hub.tool("pointer", *pygame.mouse.get_pos())
        frame = self.hub.drain(self.frame)
        pointer = None
        for op in frame.tool_operations():
            try:
                pointer = self._apply(op) or pointer
            except (IndexError, TypeError):
                raise ValueError(f"tool operation {list(op)} does not fit the record scene") from None
        scene = self.scene
        scene.feed(self._value(frame, pointer))
        scene.step(self.dt)
        self.previewing = self.previewing + 1 if scene.phase == "preview" else 0
        # The scripted performer looks at the preview for 2 s, then accepts.
        if self.script and self.previewing == int(2 / self.dt) and scene.accept() is not None:
            if self._save("saved {output}"):
                print(f"saved {self.output}")
        digest, parts = record_digest(scene)
        if self.recorder is not None:
            self.recorder.write(frame, digest, parts)
        if self.check is not None:
            self.check.check(self.frame, digest, parts)
        self.frame += 1

    def draw(self, render, alpha: float, size: tuple[int, int]) -> None:  # type: ignore[no-untyped-def]
        self.scene.draw(render)


def _record_setup(args: argparse.Namespace, size: tuple[int, int]) -> dict[str, object]:
    """Everything the take depends on, the base clip's bytes included."""
    import base64

    return {"item": args.item, "drive": args.drive, "countdown": args.countdown, "seconds": args.seconds,
            "seed": args.seed, "script": args.script, "size": list(size),
            "base": base64.b64encode(args.base.read_bytes()).decode() if args.base is not None else ""}


def _check_record_setup(setup: object) -> dict[str, object]:
    """A recorded take's set-up, every value type- and range-checked (``ValueError`` in one line)."""
    import math

    def number(key: str, lo: float, hi: float) -> None:
        v = setup.get(key)
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or not lo <= v <= hi:
            raise ValueError(f"the recorded {key} {repr(v)[:30]} is not a number in [{lo:g}, {hi:g}]")

    if not isinstance(setup, dict):
        raise ValueError("the recorded take's set-up is not an object")
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
    if not (isinstance(size, list) and len(size) == 2
            and all(isinstance(v, int) and not isinstance(v, bool) and 0 <= v <= 16384 for v in size)):
        raise ValueError("the recorded window size is not two whole numbers in 0..16384")
    return setup


def _record_scene(setup: dict[str, object]):  # type: ignore[no-untyped-def]
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
    return RecordScene(skeleton, str(setup["item"]), str(setup["drive"]), base, float(setup["countdown"]),  # type: ignore[arg-type]
                       float(setup["seconds"]), np.random.default_rng(int(setup["seed"])), root_curve=curve)  # type: ignore[arg-type]


def replay_record(recording):  # type: ignore[no-untyped-def]
    """The recorded take, rebuilt from the recording alone, checking every step (saving nothing)."""
    from input.hub import InputHub
    from input.replay import HashCheck, ReplaySource

    setup = _check_record_setup(recording.header.setup)
    return RecordActivity(_record_scene(setup), InputHub(replay=ReplaySource(recording)), script=setup.get("script"),
                          size=tuple(setup.get("size", (1280, 720))), check=HashCheck(recording))


def _record(args: argparse.Namespace) -> int:
    from engine.clipfile import ClipFileError
    from engine.render.window import NoDisplayError
    from engine.runner import Runner
    from input.hub import InputHub
    from input.recording import Recorder, RecordingHeader
    from puppetphone.runargs import run_options

    live = args.source != "mouse" and args.script is None
    runner = Runner(run_options(args, "PuppetPhone — record a cycle", pace=live and args.headless))
    try:
        setup = _record_setup(args, args.size)
        scene = _record_scene(setup)
    except (ValueError, OSError, ClipFileError) as exc:
        print(f"author record: {exc}", file=sys.stderr)
        return 2
    try:
        runner.open()
    except NoDisplayError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    hub = InputHub()
    if live:
        from input.factory import make_hub

        try:
            hub = make_hub(args.source, args.osc_host, args.osc_port, args.osc_senders, args.serial_port, args.baud,
                           silent_after=args.silent_after).start()
        except (ValueError, OSError) as exc:
            runner.close()
            print(f"author record: cannot open {args.source}: {exc}", file=sys.stderr)
            return 2
    recorder = None
    if args.record is not None:
        recorder = Recorder(args.record, RecordingHeader(game=RECORD_GAME, seed=args.seed, dt=RecordActivity.dt,
                                                         sources=[args.source], setup=setup))
    activity = RecordActivity(scene, hub, script=args.script, output=args.output, size=runner.size, recorder=recorder)
    runner.push_handlers(activity)
    try:
        result = runner.run(activity)
        if result.screenshot is not None:
            print(f"screenshot: {result.screenshot}")
        print(scene.message)
    finally:
        runner.close()
        hub.close()
        if recorder is not None:
            recorder.close()
            print(f"recorded {recorder.frames} steps to {recorder.path}", file=sys.stderr)
    return 0
