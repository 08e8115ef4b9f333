"""A game as a session's simulation: the app, its view, its keys; ``play`` and ``replay`` build it here.

:func:`build_activity` returns the one :class:`authoring.session.Session` that every tool uses too,
holding a :class:`GameSimulation`: each step the session drains the hub and hands the frame to the
app (whose input stage reads exactly that frame), steps it, hashes the world, records or verifies.
The bindings are the session's (:mod:`authoring.bindings`): the left button and the wheel go to the
mouse source (grab, walk, crouch), right-drag orbits the camera (a recorded operation, so a replay
shows the same view); R / F5 / F9 become recorded input commands (reset, save, restore); H or F1
hides and shows the help; V switches between the orbit camera and the view from the held
controller (``--view phone``: :func:`input.controller_view.controller_camera`).

A replay is the same session built from a recording's header (game, seed, setup) with a replay
hub; the session compares every step's state hash with the recorded one and ends at the first
difference.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from authoring.bindings import orbit_camera
from authoring.operations import Key, Operation, Orbit
from authoring.session import KeyUse, Session
from engine.app import App
from engine.camera import Camera, OrbitCamera
from engine.hashing import part_digests
from engine.render.scene import RenderScene
from games.base import Game
from input.controller_view import controller_camera
from input.hub import InputHub
from input.recording import Recording
from input.sample import RESET, RESTORE, SAVE, InputFrame, SourceStatus
from puppetphone.games import make_app
from puppetphone.overlay import NO_VIEW, OverlayState, draw_overlay, source_kinds
from puppetphone.registry import load_game

__all__ = ["GameSimulation", "build_activity"]

#: Keys that become recorded input commands.
COMMAND_KEYS = {"r": RESET, "f5": SAVE, "f9": RESTORE}


class _Handed:
    """The app's frame source: the frame the session drained for this step (an empty one for any other)."""

    name = "session"

    def __init__(self) -> None:
        self.frame = InputFrame()

    def frame_at(self, index: int) -> InputFrame | None:
        return self.frame if self.frame.frame == index else InputFrame(frame=index)

    def status(self) -> SourceStatus:
        return SourceStatus(self.name, connected=True)


class GameSimulation:
    """One game's app as a session's simulation (see the module docstring).

    Args:
        hub: the session's hub (its sources and statuses are what the overlay shows).
    """

    def __init__(
        self, game: Game, app: App, handed: _Handed, hub: InputHub, orbit: OrbitCamera, view: str = "orbit"
    ) -> None:
        self.game, self.app, self.hub, self.orbit, self.view = game, app, hub, orbit, view
        self._handed = handed
        self.overlay = OverlayState()
        self.fps: Callable[[], float] = lambda: 0.0  # the runner's drawn frame rate, once one runs it

    @property
    def dt(self) -> float:
        """The game's fixed step."""
        return self.app.world.dt

    @property
    def camera(self) -> Camera:
        """The held controller's view in ``phone`` view (while one drives), else the orbit camera."""
        if self.view == "phone":
            phone = controller_camera(self.app.world)
            if phone is not None:
                return phone
        return self.orbit

    def on_key(self, key: Key, hub: InputHub) -> KeyUse:
        """R / F5 / F9 into the hub as commands; H / F1 help; V view; the rest is the runner's."""
        if key.name in COMMAND_KEYS:
            hub.command(COMMAND_KEYS[key.name])
        elif key.name in ("h", "f1"):
            self.overlay.toggle_help()
        elif key.name == "v":
            if self.view == "orbit" and hub.replay is None and source_kinds(hub) <= {"mouse"}:
                self.overlay.tell(NO_VIEW, self.app.world.frame)
            else:
                self.view = "orbit" if self.view == "phone" else "phone"
        else:
            return "pass"
        return "done"

    def apply(self, op: Operation) -> None:
        """Right-drag orbits the camera; a game takes no other operation (its pointer is the mouse source)."""
        if isinstance(op, Orbit):
            orbit_camera(self.orbit, op)

    def advance(self, frame: InputFrame) -> None:
        """The app's step, its input stage reading ``frame``."""
        self._handed.frame = frame
        self.app.step()

    def digest(self) -> tuple[str, dict[str, bytes]]:
        """The world's state hash and its parts (what a game's recording has always stored)."""
        return part_digests(self.app.world)

    def ready(self) -> bool:
        """A game steps at once."""
        return True

    def ended(self) -> bool:
        """A game ends when its window closes or its replay runs out."""
        return False

    def draw(self, scene: RenderScene, alpha: float, size: tuple[int, int]) -> None:
        """The game's view and the overlay."""
        self.game.draw(self.app.world, scene, alpha)
        draw_overlay(scene, self.app.world, self.game, self.hub, self.fps(), self.app.clock.paused, self.overlay, size)

    def close(self) -> None:
        """Let the game release what it holds."""
        self.game.close(self.app.world)


def build_activity(
    game_name: str,
    seed: int,
    hub: InputHub,
    *,
    setup: dict[str, Any] | None = None,
    options: dict[str, str] | None = None,
    record: Path | None = None,
    source_label: str = "",
    verify: Recording | None = None,
    clips: dict[str, Any] | None = None,
    view: str = "orbit",
) -> Session:
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
    handed = _Handed()
    app = make_app(game_name, seed, InputHub(replay=handed), setup)
    simulation = GameSimulation(game, app, handed, hub, game.camera(), view)
    session = Session(simulation, hub, pointer_acts=False)
    if record is not None:
        session.record(record, game_name, seed, setup, source_label)
    if verify is not None:
        session.verify(verify)
    _stream_to_phones(session, simulation)
    return session


def _stream_to_phones(session: Session, simulation: GameSimulation) -> None:
    """With a web source, every step's scene goes to the connected pages too (output only)."""
    from puppetphone.web_pairing import web_sources

    for source in web_sources(session.hub):
        from input.web.viewport import PhoneViewport

        draw = simulation.game.draw_state or simulation.game.draw
        simulation.app.on_step_end.append(
            PhoneViewport(source, draw, lambda: simulation.orbit, simulation.game.snowfall)
        )
