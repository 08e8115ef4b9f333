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
    sub = parser.add_subparsers(dest="scene", metavar="SCENE")
    rec = sub.add_parser("record", help="act a cycle out with the mouse or a device; layers stack into a clip")
    rec.add_argument("--item", default="r_upper_arm", help="joint to drive (default r_upper_arm)")
    rec.add_argument("--drive", default="rotation", choices=("rotation", "translation", "scale"), help="what to drive")
    rec.add_argument("--base", type=Path, default=None, help="a looping .ppclip whose layers play back while performing")
    rec.add_argument("-o", "--output", type=Path, default=Path("performed_cycle.ppclip"), help="where accepted cycles are saved")
    rec.add_argument("--countdown", type=float, default=3.0, help="seconds of countdown (default 3)")
    rec.add_argument("--seconds", type=float, default=8.0, help="length of a take (default 8)")
    rec.add_argument("--script", choices=("loops",), default=None, help="a scripted performer instead of a hand")
    rec.add_argument("--headless", action="store_true", help="no window (EGL), for tests and screenshots")
    rec.add_argument("--frames", type=int, default=None, help="stop after N frames")
    rec.add_argument("--screenshot", type=Path, default=None, help="write the last frame as PNG")
    rec.add_argument("--size", default="1280x720", help="window size WxH")
    rec.add_argument("--seed", type=int, default=0, help="seed of the extractor's probe points")
    from input.factory import add_source_arguments

    add_source_arguments(rec)
    try:
        from puppetphone.cmd_author_edit import configure_edit
    except ModuleNotFoundError:  # the MoCurves scene is optional
        return
    configure_edit(sub.add_parser("edit", help="refine a cycle with MoCurves while it plays"))


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


def _record(args: argparse.Namespace) -> int:
    import numpy as np

    from authoring.record_scene import RecordScene, drag_rotation, mouse_point
    from engine import quat
    from engine.clipfile import ClipFileError, load_clip, save_clip
    from engine.humanoid import humanoid_skeleton
    from engine.render import RenderScene, Viewer

    try:
        width, height = (int(v) for v in args.size.lower().split("x"))
        base = load_clip(args.base) if args.base is not None else None
        skeleton = base.skeleton if base is not None else humanoid_skeleton()
        scene = RecordScene(skeleton, args.item, args.drive, base, args.countdown, args.seconds, np.random.default_rng(args.seed))
    except (ValueError, OSError, ClipFileError) as exc:
        print(f"author record: {exc}", file=sys.stderr)
        return 2
    hub = None
    if args.source != "mouse" and args.script is None:
        from input.factory import make_hub

        try:
            hub = make_hub(args.source, args.osc_host, args.osc_port, args.osc_senders, args.serial_port, args.baud).start()
        except (ValueError, OSError) as exc:
            print(f"author record: cannot open {args.source}: {exc}", file=sys.stderr)
            return 2
    viewer = Viewer.create(headless=args.headless, width=width, height=height, title="PuppetPhone — record a cycle")
    viewer.camera = scene.camera
    render = RenderScene()
    clock = None if args.headless else __import__("pygame").time.Clock()
    fps = 60.0
    frame, press, phase_acc, reference, previewing = 0, None, [0.0], None, 0
    rest = scene.rest_value()
    if args.script:
        scene.start()
    try:
        while args.frames is None or frame < args.frames:
            value = None
            for ev in viewer.poll_events():
                press, rest = _mouse(ev, scene, press, rest, args.output, save_clip)
            if getattr(viewer.target, "closed", False):
                break
            if args.script:
                value = _scripted(frame, fps, phase_acc, args.drive, scene.item_position(), rest)
            elif hub is not None:
                sample = hub.drain(frame).latest()
                if sample is not None and scene.drive == "rotation":
                    if scene.phase != "recording" or reference is None:
                        reference, rest = sample.orientation, scene.rest_value()
                    value = quat.mul(quat.mul(sample.orientation, quat.conjugate(reference)), rest)
            elif press is not None:
                import pygame

                px, py = pygame.mouse.get_pos()
                if scene.drive == "rotation":
                    value = quat.mul(rest, drag_rotation(px - press[0], py - press[1], height))
                else:
                    value = mouse_point(scene.camera, px, py, viewer.size, press[2])
            scene.feed(value)
            scene.step(1.0 / fps)
            previewing = previewing + 1 if scene.phase == "preview" else 0
            # The scripted performer looks at the preview for 2 s, then accepts.
            if args.script and previewing == int(2 * fps) and scene.accept() is not None:
                save_clip(scene.clip, args.output)  # type: ignore[arg-type]
                print(f"saved {args.output}")
            render.clear()
            scene.draw(render)
            viewer.draw(render)
            if clock is not None:
                clock.tick(fps)
            frame += 1
        if args.screenshot is not None:
            viewer.screenshot(args.screenshot)
        print(scene.message)
    finally:
        viewer.close()
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
