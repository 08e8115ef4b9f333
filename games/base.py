"""What a game gives the launcher: its options, its simulation plugin, its view.

Set-up is split in two so a recording can rebuild any session:

- :attr:`Game.prepare` reads everything from outside the program — the options typed
  on the command line, save files, photos, the user's data folder — into one explicit
  :class:`GameSetup` of plain JSON values. It runs only for a live session, and what
  it returns is written into the recording's header.
- :attr:`Game.install` is then a pure function of that setup and the world's seed: it
  reads :class:`GameSetup` from the world and nothing else (no files, no environment),
  so ``puppetphone replay FILE`` rebuilds the very session that was recorded from the
  file alone.

Everything else here only reads the world (drawing, the camera, the overlay) or acts on
it between steps in ways the recording captures (keys that reset are turned into input
by the launcher, never applied behind the recorder's back).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from engine.app import App
from engine.camera import OrbitCamera
from engine.ecs import World
from engine.render.scene import RenderScene
from engine.render.snowfall import Snowfall

__all__ = ["Game", "GameSetup", "GameOptionError", "describe_options", "parse_settings"]


class GameOptionError(ValueError):
    """A game option that does not exist or has a value the game cannot use."""


class GameSetup:
    """The explicit inputs of a game's install (a world resource; see the module docstring).

    Not hashed: it is fixed for the whole session and carried by the recording's header.
    """

    SIM_STATE = False

    def __init__(self, values: dict[str, Any] | None = None) -> None:
        self.values: dict[str, Any] = dict(values or {})

    def get(self, key: str, default: Any = None) -> Any:
        """One value of the setup."""
        return self.values.get(key, default)


def _no_lines(world: World) -> list[str]:
    return []


def _nothing_to_close(world: World) -> None:
    return None


def _options_as_setup(options: dict[str, str]) -> dict[str, Any]:
    return dict(options)


def parse_settings(pairs: list[str], declared: dict[str, str], game: str) -> dict[str, str]:
    """``["key=value", ...]`` from ``--set`` over the game's declared defaults."""
    options = dict(declared)
    for pair in pairs:
        key, eq, value = pair.partition("=")
        if not eq:
            raise GameOptionError(f"--set takes key=value, not {pair!r}")
        if key not in declared:
            known = ", ".join(declared) or "none"
            raise GameOptionError(f"{game} has no option {key!r} (options: {known})")
        options[key] = value
    return options


def describe_options(game: Game) -> list[str]:
    """``--set help``: one line per option: its type or range, what it does, its default.

    An option whose default is empty says in its help what leaving it unset means.
    """
    if not game.options:
        return [f"{game.name}: no options"]
    lines = [f"{game.name}:"]
    for key, default in game.options.items():
        shown = f"; default {default}" if default else ""
        lines.append(f"  {key:<8} {game.option_help.get(key, 'text')}{shown}")
    return lines


@dataclass(frozen=True)
class Game:
    """A playable game.

    Attributes:
        name: the name on the command line.
        install: plugin that builds the simulation (scene, puppets, rules).
        draw: fills a render scene from the world, interpolated by ``alpha``.
        draw_state: what is streamed to the phone every step (``None``: ``draw``): the game's
            drawing without what would cost too much on the wire (snowman: the 900 falling
            flakes move every step; the tracks are cells in grid order, so a new one shifts
            every row after it).
        snowfall: the falling snow ``draw`` adds, described once so a phone can move the flakes
            itself (``draw_state`` leaves them out); ``None``: no falling snow.
        camera: the starting camera.
        status: overlay lines (counters, stage) read from the world.
        controls: the start screen's help lines; a line that starts with a source kind and a
            colon (``mouse:``, ``osc:``, ``web:``, ``hid:``, ``serial:``) is shown only while that
            source drives the game.
        controls_now: the lines of ``controls`` that apply in the world's present state
            (tasbada: the current stage's); ``None``: all of them.
        options: the options ``--set key=value`` may give, with their defaults.
        option_help: per option, its type and range and what it does, one line
            (``play GAME --set help`` prints them beside the defaults).
        prepare: reads the outside world for a live session: options in, the
            :class:`GameSetup` values out (plain JSON; raises :class:`GameOptionError`).
        replay_setup: the setup a replay uses, from the one recorded (for instance
            without the paths a live game saves to: replays never write a user's files).
        close: releases what the game holds outside the simulation when the session ends
            (a webcam, a worker thread that must finish before the process exits).
    """

    name: str
    install: Callable[[App], None]
    draw: Callable[[World, RenderScene, float], None]
    camera: Callable[[], OrbitCamera]
    status: Callable[[World], list[str]] = _no_lines
    controls: tuple[str, ...] = field(default_factory=tuple)
    controls_now: Callable[[World], tuple[str, ...]] | None = None
    options: dict[str, str] = field(default_factory=dict)
    option_help: dict[str, str] = field(default_factory=dict)
    prepare: Callable[[dict[str, str]], dict[str, Any]] = _options_as_setup
    replay_setup: Callable[[dict[str, Any]], dict[str, Any]] = dict
    draw_state: Callable[[World, RenderScene, float], None] | None = None
    snowfall: Snowfall | None = None
    close: Callable[[World], None] = _nothing_to_close
