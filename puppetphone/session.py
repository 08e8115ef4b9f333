"""A game session as the runner's activity: the app, its input, recording and verification.

:class:`GameActivity` is what ``play`` and ``replay`` hand to :class:`engine.runner.Runner`:
one step is ``App.step``; drawing is the game's view plus the overlay; its event layer
feeds the mouse source, orbits the camera (right-drag) and turns R / F5 / F9 into
recorded input commands (reset, save, restore), so replays repeat them; H or F1 hides
and shows the help; V switches between the orbit camera and the view from the held
controller (``--view phone``: :func:`input.controller_view.controller_camera`).

A replay is the same activity built from a recording's header (game, seed, setup) with
a replay hub; :class:`input.replay.HashCheck` compares every step's state hash with the recorded one
and ends the activity at the first difference.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from engine.app import App
from engine.camera import Camera, OrbitCamera
from engine.render.scene import RenderScene
from engine.runner import Runner
from games.base import Game
from input.controller_view import controller_camera
from input.hub import InputHub
from input.recording import Recorder, Recording, RecordingHeader
from input.replay import HashCheck
from input.sample import RESET, RESTORE, SAVE
from puppetphone.games import load_game, make_app
from puppetphone.overlay import NO_VIEW, OverlayState, draw_overlay, source_kinds

__all__ = ["GameActivity", "build_activity"]


@dataclass
class GameActivity:
    """One game session (see the module docstring)."""

    game: Game
    app: App
    hub: InputHub
    orbit: OrbitCamera
    recorder: Recorder | None = None
    check: HashCheck | None = None
    runner: Runner | None = None
    overlay: OverlayState = field(default_factory=OverlayState)
    view: str = "orbit"
    _orbiting: bool = field(default=False, repr=False)

    @property
    def camera(self) -> Camera:
        """The camera drawn with: the held controller's view in ``phone`` view (while one drives), else the orbit."""
        if self.view == "phone":
            phone = controller_camera(self.app.world)
            if phone is not None:
                return phone
        return self.orbit

    @property
    def dt(self) -> float:
        """The game's fixed step."""
        return self.app.world.dt

    def step(self) -> None:
        """One simulation step."""
        self.app.step()

    @property
    def input_wake(self) -> threading.Event | None:
        """Set when a live reading arrives: the paced runner starts the step early for it (none in a replay)."""
        return self.hub.arrived if self.hub.replay is None else None

    def finished(self) -> bool:
        """A replay ends after its last recorded frame or at the first hash that differs."""
        if self.check is not None and not self.check.ok:
            return True
        replay = self.hub.replay
        return replay is not None and self.app.world.frame > replay.last_frame  # type: ignore[attr-defined]

    def draw(self, scene: RenderScene, alpha: float, size: tuple[int, int]) -> None:
        """The game's view and the overlay."""
        self.game.draw(self.app.world, scene, alpha)
        fps = self.runner.fps if self.runner is not None else 0.0
        draw_overlay(scene, self.app.world, self.game, self.hub, fps, self.app.clock.paused, self.overlay, size)

    def on_event(self, event: Any, runner: Runner) -> bool:
        """Mouse to the mouse source, right-drag orbits, R / F5 / F9 become recorded commands."""
        import pygame

        commands = {pygame.K_r: RESET, pygame.K_F5: SAVE, pygame.K_F9: RESTORE}
        if event.type == pygame.KEYDOWN and event.key in commands:
            self.hub.command(commands[event.key])
            return True
        if event.type == pygame.KEYDOWN and event.key in (pygame.K_h, pygame.K_F1):
            self.overlay.toggle_help()
            return True
        if event.type == pygame.KEYDOWN and event.key == pygame.K_v:
            if self.view == "orbit" and self.hub.replay is None and source_kinds(self.hub) <= {"mouse"}:
                self.overlay.tell(NO_VIEW, self.app.world.frame)
                return True
            self.view = "orbit" if self.view == "phone" else "phone"
            return True
        if event.type == pygame.MOUSEBUTTONDOWN and event.button == 3:
            self._orbiting = True
        elif event.type == pygame.MOUSEBUTTONUP and event.button == 3:
            self._orbiting = False
        elif event.type == pygame.MOUSEMOTION and self._orbiting:
            self.orbit.orbit(-0.005 * event.rel[0], -0.005 * event.rel[1])
        for source in self.hub.sources:
            handle = getattr(source, "handle_event", None)
            if handle is not None:
                handle(event, self.camera, runner.size)
        return False

    def close(self) -> None:
        """Stop the devices, let the game release what it holds, close the recording (already flushed)."""
        self.hub.close()
        self.game.close(self.app.world)
        if self.recorder is not None:
            self.recorder.close()


def build_activity(game_name: str, seed: int, hub: InputHub, *, setup: dict[str, Any] | None = None,
                   options: dict[str, str] | None = None, record: Path | None = None, source_label: str = "",
                   verify: Recording | None = None, clips: dict[str, Any] | None = None,
                   view: str = "orbit") -> GameActivity:
    """The session of ``game_name``.

    Args:
        setup: a recorded setup (replays); otherwise ``options`` go through the game's
            ``prepare``, which reads save files and pictures.
        record: write the session (its setup in the header) to this file.
        verify: compare every step's state hash with this recording's.
        clips: the authored clips to play (``engine.cliplib.embed``), over any in the setup.
        view: ``orbit`` or ``phone`` (the held controller's view; V switches).
    """
    game = load_game(game_name)
    if setup is None:
        setup = game.prepare(dict(game.options) if options is None else options)
    if clips is not None:
        setup = {**setup, "clips": clips}
    app = make_app(game_name, seed, hub, setup)
    recorder = None
    if record is not None:
        header = RecordingHeader(game=game_name, seed=seed, dt=app.world.dt, sources=[source_label], setup=setup)
        recorder = Recorder(record, header).attach(app)
    check = None
    if verify is not None:
        check = HashCheck(verify)
        app.on_step_end.append(check)
    activity = GameActivity(game, app, hub, game.camera(), recorder, check, view=view)
    _stream_to_phones(activity)
    return activity


def _stream_to_phones(activity: GameActivity) -> None:
    """With a web source, every step's scene goes to the connected pages too (output only)."""
    from input.web.server import WebSource
    from input.web.viewport import PhoneViewport

    for source in activity.hub.sources:
        if isinstance(source, WebSource):
            draw = activity.game.draw_state or activity.game.draw
            activity.app.on_step_end.append(PhoneViewport(source, draw, lambda: activity.orbit))
