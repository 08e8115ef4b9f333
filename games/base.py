"""What a game gives the launcher: its simulation plugin, its view, its keys.

The simulation part (:meth:`Game.install`) must be deterministic and headless;
everything else here only reads the world (drawing, the camera, the overlay) or
acts on it between steps in ways the recording captures (keys that reset are
turned into input by the launcher, never applied behind the recorder's back).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from engine.app import App
from engine.camera import OrbitCamera
from engine.ecs import World
from engine.render.scene import RenderScene

__all__ = ["Game"]


def _no_lines(world: World) -> list[str]:
    return []


def _no_extra(world: World) -> dict[str, Any]:
    return {}


@dataclass(frozen=True)
class Game:
    """A playable game.

    Attributes:
        name: the name on the command line.
        install: plugin that builds the simulation (scene, puppets, rules).
        draw: fills a render scene from the world, interpolated by ``alpha``.
        camera: the starting camera.
        status: overlay lines (counters, stage) read from the world.
        controls: the start screen's help lines.
        recording_extra: what a recording's header must carry to rebuild this start
            (read back by the game's install when it is replayed).
    """

    name: str
    install: Callable[[App], None]
    draw: Callable[[World, RenderScene, float], None]
    camera: Callable[[], OrbitCamera]
    status: Callable[[World], list[str]] = _no_lines
    controls: tuple[str, ...] = field(default_factory=tuple)
    recording_extra: Callable[[World], dict[str, Any]] = _no_extra
