"""The sandbox: a snowy field and one puppet (tests, first steps), with an optional prop.

Option ``scene`` (``--set scene=...``): ``empty`` (default), ``small_ball`` (a ball to
pick up one stride in front of the puppet) or ``big_ball`` (a ball too big to carry,
to roll). The recorded puppet sessions in ``tests/data`` use them.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from engine.app import App
from engine.camera import OrbitCamera
from engine.components import Grabbable
from engine.ecs import World
from engine.ragdoll.system import spawn_snowball
from engine.render.components import Appearance
from engine.statemachine.puppet import install_puppets, spawn_puppet
from games.base import Game, GameOptionError, GameSetup
from games.common import draw_world

__all__ = ["GAME", "SCENES", "SMALL_BALL", "BIG_BALL"]

SMALL_BALL = np.array([0.0, 0.14, 1.05])
BIG_BALL = np.array([0.0, 0.3, 1.35])


def _ball(world: World, centre: np.ndarray, radius: float) -> None:
    e = spawn_snowball(world, centre, radius=radius)
    world.add(e, Grabbable(radius=radius + 0.05, kind="snowball"))


SCENES: dict[str, Callable[[World], None]] = {
    "empty": lambda world: None,
    "small_ball": lambda world: _ball(world, SMALL_BALL, 0.14),
    "big_ball": lambda world: _ball(world, BIG_BALL, 0.3),
}


def prepare(options: dict[str, str]) -> dict[str, Any]:
    """Check the scene name (nothing outside the program is read)."""
    if options["scene"] not in SCENES:
        raise GameOptionError(f"sandbox scene {options['scene']!r} is not one of {', '.join(SCENES)}")
    return dict(options)


def install(app: App) -> None:
    """One puppet at the origin facing the camera side (+Z), and the scene's prop."""
    app.add_plugin(install_puppets)
    spawn_puppet(app.world, (0.0, 0.0, 0.0), 0.0, extra=(Appearance(color=(0.85, 0.35, 0.25)),))
    setup = app.world.try_resource(GameSetup)
    SCENES[setup.get("scene", "empty") if setup is not None else "empty"](app.world)


def camera() -> OrbitCamera:
    """A three-quarter view of the field."""
    return OrbitCamera(target=[0.0, 0.8, 0.0], yaw=0.5, pitch=0.35, distance=6.0)


GAME = Game(name="sandbox", install=install, draw=draw_world, camera=camera,
            options={"scene": "empty"}, prepare=prepare)
