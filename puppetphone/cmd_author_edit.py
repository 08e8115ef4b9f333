"""``puppetphone author edit CLIP``: refine a cycle with MoCurves while it plays.

``CLIP`` is a ``.ppclip`` file (a recorded cycle; its ``.mocurves.json`` side file is
picked up) or the name of a default clip (``walk``, ``run``, …). Ctrl+S saves atomically
to ``--output`` (default: beside the input, ``<name>_edited.ppclip``); ``--export`` writes
BVH/glTF/ppclip copies at the end. ``--headless --frames N --screenshot PNG`` runs the
scene without a window (CI, screenshots). Wired as ``configure_edit``/``run_edit`` so the
``author`` command can host it beside ``author record``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

__all__ = ["configure_edit", "run_edit"]


def configure_edit(parser: argparse.ArgumentParser) -> None:
    """Add the ``author edit`` arguments."""
    from puppetphone.runargs import add_run_arguments

    parser.add_argument("clip", help="a .ppclip cycle, or a default clip name (walk, run, crouch_walk, idle…)")
    parser.add_argument("-o", "--output", type=Path, default=None, help="where Ctrl+S saves (.ppclip)")
    parser.add_argument("--export", type=Path, action="append", default=[],
                        help="also write the edited cycle here on exit (.ppclip, .bvh, .glb, .gltf); repeatable")  # fmt: skip
    add_run_arguments(parser)


def _open(spec: str):  # type: ignore[no-untyped-def]
    from authoring.mocurves import EditSession, load_session
    from engine.clips import default_clips

    path = Path(spec)
    if path.exists() and path.suffix.lower() != ".ppclip":
        raise ValueError(f"{path} is not a clip file: author edit opens a .ppclip cycle or a default clip "
                         f"({', '.join(default_clips())})")
    if path.suffix.lower() == ".ppclip":
        return load_session(path), path.with_name(path.stem + "_edited.ppclip")
    clips = default_clips()
    if spec not in clips:
        raise ValueError(f"{spec!r} is neither a .ppclip file nor a default clip ({', '.join(clips)})")
    return EditSession(clips[spec]), Path(f"{spec}_edited.ppclip")


class EditActivity:
    """The MoCurves scene as the runner's activity: the loop plays at the fixed 60 Hz step."""

    dt = 1.0 / 60.0

    def __init__(self, edit, session, output: Path) -> None:  # type: ignore[no-untyped-def]
        self.edit, self.session, self.output = edit, session, output
        self.camera = edit.camera
        self._orbiting = [False]

    def finished(self) -> bool:
        return False

    def step(self) -> None:
        self.edit.step(self.dt)

    def draw(self, scene, alpha: float, size: tuple[int, int]) -> None:  # type: ignore[no-untyped-def]
        self.edit.size = size
        self.edit.draw(scene)

    def on_event(self, ev, runner) -> bool:  # type: ignore[no-untyped-def]
        return _handle(ev, self.edit, self.session, self.output, self._orbiting)


def run_edit(args: argparse.Namespace) -> int:
    """Open the clip, run the scene until the window closes (or ``--frames``), save/export."""
    from authoring.edit_scene import EditScene
    from authoring.mocurves import export_clip
    from engine.render.window import NoDisplayError
    from engine.runner import Runner
    from puppetphone.runargs import run_options

    from authoring.mocurves.storage import EXPORT_SUFFIXES

    for path in args.export:
        if path.suffix.lower() not in EXPORT_SUFFIXES:
            print(f"error: cannot export {path}: use one of {', '.join(EXPORT_SUFFIXES)}", file=sys.stderr)
            return 2
    try:
        session, default_out = _open(args.clip)
    except (ValueError, OSError) as exc:
        print(f"cannot open {args.clip!r}: {exc}", file=sys.stderr)
        return 2
    output = args.output or default_out
    runner = Runner(run_options(args, "PuppetPhone — MoCurves"))
    try:
        runner.open()
    except NoDisplayError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    activity = EditActivity(EditScene(session, runner.size), session, output)
    runner.push_handlers(activity)
    try:
        result = runner.run(activity)
        if result.screenshot is not None:
            print(f"screenshot: {result.screenshot}")
        for path in args.export:
            export_clip(session.clip, path)
            print(f"exported {path}")
    finally:
        runner.close()
    return 0


def _handle(ev, edit, session, output: Path, orbiting: list[bool]) -> bool:  # type: ignore[no-untyped-def]
    """Translate one pygame event into scene calls; ``orbiting[0]`` tracks a middle-drag orbit."""
    import pygame

    from authoring.mocurves import save_session

    mods = pygame.key.get_mods()
    shift = bool(mods & pygame.KMOD_SHIFT)
    if ev.type == pygame.MOUSEBUTTONDOWN and ev.button in (1, 3):
        edit.press(*ev.pos, shift=shift or ev.button == 3)
    elif ev.type == pygame.MOUSEBUTTONDOWN and ev.button == 2:
        orbiting[0] = True
    elif ev.type == pygame.MOUSEBUTTONUP and ev.button in (1, 3):
        edit.release(*ev.pos)
    elif ev.type == pygame.MOUSEBUTTONUP and ev.button == 2:
        orbiting[0] = False
    elif ev.type == pygame.MOUSEMOTION:
        if orbiting[0]:
            edit.camera.orbit(-ev.rel[0] * 0.01, ev.rel[1] * 0.01)
        else:
            edit.move(*ev.pos)
    elif ev.type == pygame.MOUSEWHEEL:
        edit.camera.zoom(0.9 if ev.y > 0 else 1.1)
    elif ev.type == pygame.KEYDOWN:
        name = pygame.key.name(ev.key)
        ctrl = bool(mods & pygame.KMOD_CTRL)
        if ctrl and name == "s":
            save_session(session, output)
            edit.message = f"saved {output}"
        else:
            edit.key(name, ctrl=ctrl, shift=shift)
    else:
        return False
    return True
