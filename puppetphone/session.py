"""A play session: the game's app, its input, an optional recorder, and the frame loop.

Two ways to run:

- **windowed** — a pygame window; real elapsed time goes through the fixed-step
  clock (``App.tick``), the scene is drawn every display frame and interpolated with
  the clock's ``alpha``; mouse events feed the mouse source; right-drag orbits.
- **headless** — no display. With a live source (mouse, osc, hid, serial) steps
  are paced to real time so a phone can drive it; with a replay or no source it
  runs as fast as it can. Only the last frame is rendered, for ``--screenshot``.

Keys (windowed): Esc quits, P pauses, ``.`` single-steps while paused, H or F1 hides
and shows the help; R resets the game, F5 saves and F9 restores it (games that keep a
field: snowman). The last three go through the hub as recorded input events, so
replays repeat them.
"""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

from engine.app import App
from engine.camera import OrbitCamera
from engine.render.scene import RenderScene
from games.base import Game
from input.hub import InputHub
from input.recording import Recorder, RecordingHeader
from input.sample import RESET, RESTORE, SAVE
from puppetphone.overlay import OverlayState, draw_overlay
from puppetphone.games import load_game, make_app

__all__ = ["SessionOptions", "Session"]


@dataclass
class SessionOptions:
    """What the command line chose for a session."""

    game: str
    seed: int = 0
    headless: bool = False
    frames: int | None = None
    screenshot: Path | None = None
    record: Path | None = None
    width: int = 1280
    height: int = 720
    source_label: str = "mouse"
    extra: dict[str, object] = field(default_factory=dict)


class Session:
    """Owns the app, hub, recorder, render target and camera of one run."""

    def __init__(self, options: SessionOptions, hub: InputHub) -> None:
        self.options = options
        self.hub = hub
        self.game: Game = load_game(options.game)
        self.app: App = make_app(options.game, options.seed, hub)
        self.camera: OrbitCamera = self.game.camera()
        self.scene = RenderScene()
        self.overlay = OverlayState()
        self.recorder: Recorder | None = None
        if options.record is not None:
            header = RecordingHeader(game=options.game, seed=options.seed, dt=self.app.world.dt, sources=[options.source_label],
                                     extra=self.game.recording_extra(self.app.world))
            self.recorder = Recorder(options.record, header).attach(self.app)
        self._target = None
        self._renderer = None
        self.fps = 0.0

    # -- rendering ----------------------------------------------------------------------
    def _ensure_renderer(self) -> None:
        if self._target is None:
            from engine.render.renderer import Renderer
            from engine.render.target import make_target

            self._target = make_target(self.options.headless, self.options.width, self.options.height)
            self._renderer = Renderer(self._target.ctx)

    def draw(self) -> None:
        """Draw the current world state (interpolated) into the target."""
        self._ensure_renderer()
        assert self._target is not None and self._renderer is not None
        self.scene.clear()
        alpha = self.app.clock.alpha
        self.game.draw(self.app.world, self.scene, alpha)
        draw_overlay(self.scene, self.app.world, self.game, self.hub, self.fps, self.app.clock.paused, self.overlay)
        fb = self._target.begin()
        self._renderer.render(self.scene, self.camera, fb)
        self._target.end()

    def screenshot(self, path: Path) -> Path:
        """Render the current state and write it as PNG."""
        self.draw()
        assert self._target is not None
        return self._target.screenshot(path)

    # -- running ------------------------------------------------------------------------
    def _done(self, steps: int) -> bool:
        if self.options.frames is not None and steps >= self.options.frames:
            return True
        replay = self.hub.replay
        return replay is not None and self.options.frames is None and self.app.world.frame > replay.last_frame  # type: ignore[attr-defined]

    def run_headless(self) -> int:
        """Step as fast as allowed (paced for live sources) until done; returns steps run."""
        pacer = None
        if self.hub.live:
            from input.pacing import RealTimePacer

            pacer = RealTimePacer(self.app.world.dt)
        steps = 0
        while not self._done(steps):
            if pacer is not None:
                pacer.wait()
            self.app.step()
            steps += 1
        return steps

    def run_window(self) -> int:
        """The interactive loop; returns steps run."""
        import pygame

        self._ensure_renderer()
        assert self._target is not None
        mouse = next((s for s in self.hub.sources if hasattr(s, "handle_event")), None)
        last = time.perf_counter()
        steps = 0
        orbiting = False
        fps_frames, fps_t0 = 0, last
        while not self._done(steps):
            for ev in self._target.poll_events():
                if ev.type == pygame.QUIT or (ev.type == pygame.KEYDOWN and ev.key == pygame.K_ESCAPE):
                    return steps
                if ev.type == pygame.KEYDOWN:
                    self._key(ev.key)
                if ev.type == pygame.MOUSEBUTTONDOWN and ev.button == 3:
                    orbiting = True
                elif ev.type == pygame.MOUSEBUTTONUP and ev.button == 3:
                    orbiting = False
                elif ev.type == pygame.MOUSEMOTION and orbiting:
                    self.camera.orbit(-0.005 * ev.rel[0], -0.005 * ev.rel[1])
                if mouse is not None:
                    mouse.handle_event(ev, self.camera, self._target.size)
            now = time.perf_counter()
            steps += self.app.tick(min(now - last, 0.25))
            last = now
            self.draw()
            fps_frames += 1
            if now - fps_t0 >= 0.5:
                self.fps, fps_frames, fps_t0 = fps_frames / (now - fps_t0), 0, now
        return steps

    def _key(self, key: int) -> None:
        import pygame

        clock = self.app.clock
        commands = {pygame.K_r: RESET, pygame.K_F5: SAVE, pygame.K_F9: RESTORE}
        if key == pygame.K_p:
            clock.resume() if clock.paused else clock.pause()
        elif key == pygame.K_PERIOD:
            clock.request_step()
        elif key in (pygame.K_h, pygame.K_F1):
            self.overlay.toggle_help()
        elif key in commands:
            self.hub.command(commands[key])

    def run(self) -> int:
        """Run to the end; write the screenshot; close everything. Returns the exit code."""
        self.hub.start()
        try:
            steps = self.run_headless() if self.options.headless else self.run_window()
            if self.options.screenshot is not None:
                path = self.screenshot(self.options.screenshot)
                print(f"screenshot: {path}")
            print(f"ran {steps} steps of {self.options.game}")
            return 0
        finally:
            self.close()

    def close(self) -> None:
        """Stop devices, close the recording (everything written is already flushed)."""
        self.hub.close()
        if self.recorder is not None:
            self.recorder.close()
            print(f"recorded {self.recorder.frames} frames to {self.recorder.path}", file=sys.stderr)
        if self._target is not None:
            if self._renderer is not None:
                self._renderer.release()
            self._target.close()
            self._target = None
