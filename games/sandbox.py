"""The sandbox: a snowy field and its puppets (tests, first steps, crowds), with an optional prop.

Options (``--set key=value``):

- ``puppets`` (default 1): with more than one it is a crowd — the first puppet stands at
  the origin and is the only one a stick can grab; the others are spread on a grid
  around it and wander the field at paces from a slow walk to a run
  (:mod:`games.wander`), all from the world's seeded generator so a crowd replays bit
  for bit (``puppetphone play sandbox --set puppets=100``; ``bench crowd`` measures it).
- ``scene``: ``empty`` (default), ``small_ball`` (a ball to pick up one stride in front of
  the puppet) or ``big_ball`` (a ball too big to carry, to roll). The recorded puppet
  sessions in ``tests/data`` use them.
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
from games.common import draw_world, spawn_player
from games.wander import Wanderer, install_wander

__all__ = ["GAME", "SCENES", "SMALL_BALL", "BIG_BALL", "SPACING", "PACES", "MAX_PUPPETS"]

SMALL_BALL = np.array([0.0, 0.14, 1.05])
BIG_BALL = np.array([0.0, 0.3, 1.35])
SPACING = 1.6  # m between the crowd's starting places
PACES = (0.6, 2.8)  # m/s: the slowest and fastest wanderer
MAX_PUPPETS = 1000


def _ball(world: World, centre: np.ndarray, radius: float) -> None:
    e = spawn_snowball(world, centre, radius=radius)
    world.add(e, Grabbable(radius=radius + 0.05, kind="snowball"))


SCENES: dict[str, Callable[[World], None]] = {
    "empty": lambda world: None,
    "small_ball": lambda world: _ball(world, SMALL_BALL, 0.14),
    "big_ball": lambda world: _ball(world, BIG_BALL, 0.3),
}


OPTION_HELP = {
    "scene": f"{'|'.join(SCENES)}: what stands beside the puppet",
    "puppets": f"whole number 1–{MAX_PUPPETS}: the grabbable puppet plus a wandering crowd (same as --puppets N)",
}


def prepare(options: dict[str, str]) -> dict[str, Any]:
    """Check the options (nothing outside the program is read)."""
    if options["scene"] not in SCENES:
        raise GameOptionError(f"sandbox scene {options['scene']!r} is not one of {', '.join(SCENES)}")
    try:
        puppets = int(options["puppets"])
    except ValueError:
        raise GameOptionError(f"sandbox puppets must be a whole number, not {options['puppets']!r}") from None
    if not 1 <= puppets <= MAX_PUPPETS:
        raise GameOptionError(f"sandbox puppets must be from 1 to {MAX_PUPPETS}, not {puppets}")
    return {"scene": options["scene"], "puppets": puppets}


def install(app: App) -> None:
    """The grabbable puppet at the origin facing the camera side (+Z), the crowd, the scene's prop."""
    setup = app.world.try_resource(GameSetup) or GameSetup()
    puppets = int(setup.get("puppets", 1))
    if not 1 <= puppets <= MAX_PUPPETS:
        raise GameOptionError(f"sandbox puppets must be from 1 to {MAX_PUPPETS}, not {puppets}")
    app.add_plugin(install_puppets)
    world = app.world
    spawn_player(world, (0.0, 0.0, 0.0), 0.0, color=(0.85, 0.35, 0.25))
    if puppets > 1:
        app.add_plugin(install_wander)
        _spawn_crowd(world, puppets - 1)
    SCENES[setup.get("scene", "empty")](world)


def _spawn_crowd(world: World, n: int) -> None:
    side = int(np.ceil(np.sqrt(n + 1)))
    half = 0.5 * SPACING * side + 4.0
    places = [(i % side, i // side) for i in range(1, n + 1)]  # grid cell 0 is the grabbable puppet's
    for k, (i, j) in enumerate(places):
        pos = np.array([(i - 0.5 * (side - 1)) * SPACING, 0.0, (j - 0.5 * (side - 1)) * SPACING])
        pos -= np.array([(0 - 0.5 * (side - 1)) * SPACING, 0.0, (0 - 0.5 * (side - 1)) * SPACING])
        heading = float(world.rng.uniform(-np.pi, np.pi))
        goal = np.array([world.rng.uniform(-half, half), 0.0, world.rng.uniform(-half, half)])
        pace = float(world.rng.uniform(*PACES))
        e = spawn_puppet(
            world,
            pos,
            heading,
            name=f"wanderer {k + 1}",
            extra=(Appearance(color=(0.3, 0.45, 0.8)), Wanderer(pace, goal, half)),
        )
        world.remove(e, Grabbable)


def camera() -> OrbitCamera:
    """A three-quarter view of the field."""
    return OrbitCamera(target=np.array([0.0, 0.8, 0.0]), yaw=0.5, pitch=0.35, distance=6.0)


def replay_setup(recorded: dict[str, Any]) -> dict[str, Any]:
    """A recording's set-up, checked like the options it came from (``GameOptionError`` in one line)."""
    scene, puppets = recorded.get("scene", "empty"), recorded.get("puppets", 1)
    if not isinstance(scene, str) or scene not in SCENES:
        raise GameOptionError(f"the recorded sandbox scene {repr(scene)[:40]} is not one of {', '.join(SCENES)}")
    if not isinstance(puppets, int) or isinstance(puppets, bool) or not 1 <= puppets <= MAX_PUPPETS:
        raise GameOptionError(
            f"the recorded sandbox puppets {repr(puppets)[:40]} is not a number from 1 to {MAX_PUPPETS}"
        )
    return dict(recorded)


GAME = Game(
    name="sandbox",
    install=install,
    draw=draw_world,
    camera=camera,
    options={"scene": "empty", "puppets": "1"},
    option_help=OPTION_HELP,
    prepare=prepare,
    replay_setup=replay_setup,
)
