"""The sandbox: a snowy field and its puppets, nothing else (tests, first steps, crowds).

With ``puppets=1`` (the default) it is one puppet at the origin. With more it is a
crowd: the first puppet stands at the origin and is the only one a stick can grab;
the others are spread on a grid around it and wander the field at paces from a slow
walk to a run (:mod:`games.wander`), all from the world's seeded generator so a crowd
replays bit for bit. ``puppetphone play sandbox --puppets N`` uses :func:`game`.
"""

from __future__ import annotations

from functools import partial
from typing import Any

import numpy as np

from engine.app import App
from engine.camera import OrbitCamera
from engine.components import Grabbable
from engine.ecs import World
from engine.render.components import Appearance
from engine.statemachine.puppet import PuppetBody, install_puppets, spawn_puppet
from games.base import Game
from games.common import draw_world
from games.wander import Wanderer, install_wander

__all__ = ["GAME", "game", "install", "SPACING", "PACES"]

SPACING = 1.6  # m between the crowd's starting places
PACES = (0.6, 2.8)  # m/s: the slowest and fastest wanderer


def install(app: App, puppets: int = 1) -> None:
    """One grabbable puppet at the origin facing the camera side (+Z), and ``puppets - 1`` wanderers."""
    if puppets < 1:
        raise ValueError(f"the sandbox needs at least one puppet, got {puppets}")
    install_puppets(app)
    world = app.world
    spawn_puppet(world, (0.0, 0.0, 0.0), 0.0, extra=(Appearance(color=(0.85, 0.35, 0.25)),))
    if puppets > 1:
        install_wander(app)
        _spawn_crowd(world, puppets - 1)


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
        e = spawn_puppet(world, pos, heading, name=f"wanderer {k + 1}",
                         extra=(Appearance(color=(0.3, 0.45, 0.8)), Wanderer(pace, goal, half)))
        world.remove(e, Grabbable)


def camera() -> OrbitCamera:
    """A three-quarter view of the field."""
    return OrbitCamera(target=[0.0, 0.8, 0.0], yaw=0.5, pitch=0.35, distance=6.0)


def _puppet_count(world: World) -> dict[str, Any]:
    return {"puppets": len(world.query(PuppetBody))}


def game(puppets: int = 1) -> Game:
    """The sandbox with ``puppets`` puppets (what ``play sandbox --puppets N`` runs)."""
    install_n = partial(install, puppets=puppets) if puppets != 1 else install
    return Game(name="sandbox", install=install_n, draw=draw_world, camera=camera, recording_extra=_puppet_count)


GAME = game()
