"""``puppetphone author record|edit``: the authoring scenes.

``author record`` acts a motion cycle out (:mod:`authoring.record_scene`)::

    puppetphone author record --item r_lower_arm --drive rotation [--source mouse|osc|hid|serial]
                              [--base CYCLE.ppclip] [-o OUT.ppclip] [--countdown 3] [--seconds 8]
                              [--headless --frames N --screenshot PNG --script loops]

Mouse: hold the left button and move in loops — for a rotation the drag from the press
point turns the joint, for the root's translation the cursor is the position. A phone,
HID or serial device drives a rotation with its orientation (relative to where it
pointed when the take began). Keys: R record, Space stop, Enter accept, Backspace retry,
Ctrl+S save; right-drag orbits. Every accepted layer is saved to ``-o`` at once.

``--script loops`` replaces the hand with a scripted performer (loops of ±15 % tempo
jitter, a little tremor): a demo, and what the headless test runs.

``author edit`` is the MoCurves scene (``puppetphone.cmd_author_edit``).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

__all__ = ["configure", "run"]


def configure(parser: argparse.ArgumentParser) -> None:
    """Add ``record`` and ``edit`` sub-commands."""
    from puppetphone.runargs import add_run_arguments

    sub = parser.add_subparsers(dest="scene", metavar="SCENE")
    record_help = "act a cycle out with the mouse or a device; layers stack into a clip"
    rec = sub.add_parser("record", help=record_help, description=record_help)
    rec.set_defaults(_parser=rec)
    rec.add_argument("--item", default="r_upper_arm", help="joint to drive (default r_upper_arm)")
    rec.add_argument("--drive", default="rotation", choices=("rotation", "translation", "scale"), help="what to drive")
    rec.add_argument("--base", type=Path, default=None, help="a looping .ppclip whose layers play back while performing")
    rec.add_argument("-o", "--output", type=Path, default=Path("performed_cycle.ppclip"), help="where accepted cycles are saved")
    rec.add_argument("--countdown", type=float, default=3.0, help="seconds of countdown (default 3)")
    rec.add_argument("--seconds", type=float, default=8.0, help="length of a take (default 8)")
    rec.add_argument("--script", choices=("loops",), default=None, help="a scripted performer instead of a hand")
    add_run_arguments(rec)
    rec.add_argument("--seed", type=int, default=0, help="seed of the extractor's probe points")
    from input.factory import add_source_arguments

    add_source_arguments(rec)
    try:
        from puppetphone.cmd_author_edit import configure_edit
    except ModuleNotFoundError:  # the MoCurves scene is optional
        return
    edit_help = "refine a cycle with MoCurves while it plays"
    edit = sub.add_parser("edit", help=edit_help, description=edit_help)
    edit.set_defaults(_parser=edit)
    configure_edit(edit)


def run(args: argparse.Namespace) -> int:
    """Dispatch to the chosen scene."""
    if args.scene == "edit":
        from puppetphone.cmd_author_edit import run_edit

        return run_edit(args)
    if args.scene != "record":
        print("choose a scene: puppetphone author record|edit", file=sys.stderr)
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
    if drive == "translation":
        return centre + np.array([0.15 * np.sin(p), 0.08 * np.sin(2 * p) + tremor, 0.0])
    q = drag_rotation(260 * np.sin(p) + 40 * tremor, 160 * np.sin(2 * p + 0.5), 720)
    from engine import quat

    return quat.mul(rest, q)


class RecordActivity:
    """The record scene as the runner's activity: one step feeds the performer's value.

    The performer is the scripted loops, a device (its orientation relative to where it
    pointed when the take began) or the mouse (a drag from the press point); the runner
    calls :meth:`step` at the fixed 60 Hz whatever the frame rate, so the countdown and
    the performer's tempo are real time.
    """

    dt = 1.0 / 60.0

    def __init__(self, scene, args: argparse.Namespace, hub) -> None:  # type: ignore[no-untyped-def]
        self.scene, self.args, self.hub = scene, args, hub
        self.camera = scene.camera
        self.frame, self.previewing = 0, 0
        self.press: tuple[int, int, object] | None = None
        self.phase_acc = [0.0]
        self.reference = None
        self.rest = scene.rest_value()
        self.size = args.size
        if args.script:
            scene.start()

    def finished(self) -> bool:
        return False

    def _value(self):  # type: ignore[no-untyped-def]
        from authoring.record_scene import drag_rotation, mouse_point
        from engine import quat

        scene, fps = self.scene, 1.0 / self.dt
        if self.args.script:
            return _scripted(self.frame, fps, self.phase_acc, self.args.drive, scene.item_position(), self.rest)
        if self.hub is not None:
            sample = self.hub.drain(self.frame).latest()
            if sample is None or scene.drive != "rotation":
                return None
            if scene.phase != "recording" or self.reference is None:
                self.reference, self.rest = sample.orientation, scene.rest_value()
            return quat.mul(quat.mul(sample.orientation, quat.conjugate(self.reference)), self.rest)
        if self.press is None:
            return None
        import pygame

        px, py = pygame.mouse.get_pos()
        if scene.drive == "rotation":
            return quat.mul(self.rest, drag_rotation(px - self.press[0], py - self.press[1], self.size[1]))
        return mouse_point(scene.camera, px, py, self.size, self.press[2])

    def step(self) -> None:
        from engine.clipfile import save_clip

        scene = self.scene
        scene.feed(self._value())
        scene.step(self.dt)
        self.previewing = self.previewing + 1 if scene.phase == "preview" else 0
        # The scripted performer looks at the preview for 2 s, then accepts.
        if self.args.script and self.previewing == int(2 / self.dt) and scene.accept() is not None:
            save_clip(scene.clip, self.args.output)  # type: ignore[arg-type]
            print(f"saved {self.args.output}")
        self.frame += 1

    def draw(self, render, alpha: float, size: tuple[int, int]) -> None:  # type: ignore[no-untyped-def]
        self.size = size
        self.scene.draw(render)

    def on_event(self, ev, runner) -> bool:  # type: ignore[no-untyped-def]
        from engine.clipfile import save_clip

        self.press, self.rest = _mouse(ev, self.scene, self.press, self.rest, self.args.output, save_clip)
        return False


def _record(args: argparse.Namespace) -> int:
    import numpy as np

    from authoring.record_scene import RecordScene
    from engine.clipfile import ClipFileError, load_clip
    from engine.humanoid import humanoid_skeleton
    from engine.render.window import NoDisplayError
    from engine.runner import Runner
    from puppetphone.runargs import run_options

    try:
        base = load_clip(args.base) if args.base is not None else None
        skeleton = base.skeleton if base is not None else humanoid_skeleton()
        scene = RecordScene(skeleton, args.item, args.drive, base, args.countdown, args.seconds, np.random.default_rng(args.seed))
    except (ValueError, OSError, ClipFileError) as exc:
        print(f"author record: {exc}", file=sys.stderr)
        return 2
    live = args.source != "mouse" and args.script is None
    runner = Runner(run_options(args, "PuppetPhone — record a cycle", pace=live and args.headless))
    try:
        runner.open()
    except NoDisplayError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    hub = None
    if live:
        from input.factory import make_hub

        try:
            hub = make_hub(args.source, args.osc_host, args.osc_port, args.osc_senders, args.serial_port, args.baud).start()
        except (ValueError, OSError) as exc:
            runner.close()
            print(f"author record: cannot open {args.source}: {exc}", file=sys.stderr)
            return 2
    activity = RecordActivity(scene, args, hub)
    runner.push_handlers(activity)
    try:
        result = runner.run(activity)
        if result.screenshot is not None:
            print(f"screenshot: {result.screenshot}")
        print(scene.message)
    finally:
        runner.close()
        if hub is not None:
            hub.close()
    return 0


def _mouse(ev, scene, press, rest, output: Path, save_clip):  # type: ignore[no-untyped-def]
    """One pygame event: press/release the performing drag, keys, right-drag orbit."""
    import pygame

    if ev.type == pygame.MOUSEBUTTONDOWN and ev.button == 1:
        return (ev.pos[0], ev.pos[1], scene.item_position()), scene.rest_value()
    if ev.type == pygame.MOUSEBUTTONUP and ev.button == 1:
        return None, rest
    if ev.type == pygame.MOUSEMOTION and ev.buttons[2]:
        scene.camera.orbit(-ev.rel[0] * 0.01, ev.rel[1] * 0.01)
    elif ev.type == pygame.MOUSEWHEEL:
        scene.camera.zoom(0.9 if ev.y > 0 else 1.1)
    elif ev.type == pygame.KEYDOWN:
        name = pygame.key.name(ev.key)
        if name == "s" and pygame.key.get_mods() & pygame.KMOD_CTRL and scene.clip is not None:
            save_clip(scene.clip, output)
            scene.message = f"saved {output}"
        elif name in ("return", "enter") and scene.accept() is not None:
            save_clip(scene.clip, output)
            scene.message = f"layer accepted and saved to {output}; R records another"
        else:
            scene.key(name)
    return press, rest
