"""``puppetphone author curves CLIP``: edit a keyframed clip's motion curves (thesis ch. 4).

``CLIP`` is a default clip's name (``walk``, ``run``, …; keyed every 6 frames) or a
``.ppclip`` (with its ``.ppkeys`` side file when it has one, else keyed every 3 frames,
which reproduces its frames). Ctrl+S saves the baked clip and its keys atomically to
``--output`` (default ``<name>_curves.ppclip``); ``--export`` writes glTF (keys and tangents as CUBICSPLINE), BVH or
ppclip (the baked clip) at the end. ``--headless --frames N --screenshot PNG`` runs without a
window; ``--script drag`` plays a scripted gesture (select the left hand, pin both feet,
drag the hand's trajectory up and forward at frame 15) for tests and screenshots.
The same runner and conventions as ``author edit``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

__all__ = ["configure_curves", "run_curves", "CurvesActivity"]


def configure_curves(parser: argparse.ArgumentParser) -> None:
    """Add the ``author curves`` arguments."""
    from puppetphone.runargs import add_run_arguments

    parser.add_argument("clip", help="a default clip name (walk, run, …) or a .ppclip")
    parser.add_argument("-o", "--output", type=Path, default=None, help="where Ctrl+S saves (.ppclip + .ppkeys)")
    parser.add_argument("--export", type=Path, action="append", default=[],
                        help="also write the baked clip here on exit (.ppclip, .bvh, .glb, .gltf); repeatable")  # fmt: skip
    parser.add_argument("--joint", default="l_hand", help="the joint whose trajectory is shown (default l_hand)")
    parser.add_argument("--script", choices=("drag",), default=None, help="a scripted gesture instead of a hand")
    add_run_arguments(parser)


class CurvesActivity:
    """The curves scene as the runner's activity; events go straight to the scene."""

    dt = 1.0 / 60.0

    def __init__(self, scene, output: Path, script: str | None = None) -> None:  # type: ignore[no-untyped-def]
        self.scene, self.output, self.script = scene, output, script
        self.camera = scene.camera
        self.frame = 0
        self._orbiting = False

    def finished(self) -> bool:
        return False

    def on_event(self, ev, runner) -> bool:  # type: ignore[no-untyped-def]
        import pygame

        s = self.scene
        try:
            mods = ev.mod if ev.type == pygame.KEYDOWN else pygame.key.get_mods()
        except pygame.error:
            mods = 0
        shift, ctrl = bool(mods & pygame.KMOD_SHIFT), bool(mods & pygame.KMOD_CTRL)
        if ev.type == pygame.MOUSEBUTTONDOWN and ev.button in (1, 3):
            s.press(*ev.pos, shift=shift or ev.button == 3)
        elif ev.type == pygame.MOUSEBUTTONDOWN and ev.button == 2:
            self._orbiting = True
        elif ev.type == pygame.MOUSEBUTTONUP and ev.button in (1, 3):
            s.release(*ev.pos)
        elif ev.type == pygame.MOUSEBUTTONUP and ev.button == 2:
            self._orbiting = False
        elif ev.type == pygame.MOUSEMOTION:
            if self._orbiting:
                s.camera.orbit(-ev.rel[0] * 0.01, ev.rel[1] * 0.01)
            else:
                s.move(*ev.pos)
        elif ev.type == pygame.MOUSEWHEEL:
            s.camera.zoom(0.9 if ev.y > 0 else 1.1)
        elif ev.type == pygame.KEYDOWN and ctrl and ev.key == pygame.K_s:
            self.save()
        elif ev.type == pygame.KEYDOWN and ev.key not in (pygame.K_ESCAPE, pygame.K_p if ctrl else -1):
            s.key(pygame.key.name(ev.key), ctrl=ctrl, shift=shift)
        else:
            return False
        return True

    def save(self) -> None:
        from authoring.keyframe_curves.session import save_curves
        from puppetphone.saving import save_or_say

        self.scene.message = save_or_say(lambda: save_curves(self.scene.session.clip, self.output), self.output)

    def _scripted(self) -> None:
        """Frame 1: pin the feet and aim at frame 15; frames 2–21: drag the hand there in 20 moves."""
        s = self.scene
        if self.frame == 1:
            s.joint = "l_hand" if "l_hand" in s.session.clip.skeleton.names else s.joint
            for foot in ("l_foot", "r_foot"):
                if foot in s.session.clip.skeleton.names:
                    s.session.toggle_hold(foot, 0, 30)
            s.frame = 15
            self._from = s.camera.project(s.trajectory()[15][None], *s.size)[0]
            s.press(*self._from)
        elif 2 <= self.frame <= 21 and s.gesture is not None:
            k = (self.frame - 1) / 20.0
            s.move(self._from[0] - 35.0 * k, self._from[1] - 40.0 * k)
            if self.frame == 21:
                s.release(self._from[0] - 35.0, self._from[1] - 40.0)

    def step(self) -> None:
        self.frame += 1
        if self.script == "drag":
            self._scripted()
        self.scene.step(self.dt)

    def draw(self, scene, alpha: float, size: tuple[int, int]) -> None:  # type: ignore[no-untyped-def]
        self.scene.size = size
        self.scene.draw(scene)


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
    from puppetphone.runargs import run_options

    for path in args.export:
        if path.suffix.lower() not in EXPORT_SUFFIXES:
            print(f"error: cannot export {path}: use one of {', '.join(EXPORT_SUFFIXES)}", file=sys.stderr)
            return 2
    try:
        session = CurveSession.from_spec(args.clip)
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
    activity = CurvesActivity(CurvesScene(session, runner.size, args.joint), output, args.script)
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
    return 0
