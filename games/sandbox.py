"""The sandbox: a snowy field and one puppet, nothing else (tests, first steps)."""

from __future__ import annotations

from engine.app import App
from engine.camera import OrbitCamera
from engine.render.components import Appearance
from engine.statemachine.puppet import install_puppets, spawn_puppet
from games.base import Game
from games.common import draw_world

__all__ = ["GAME"]


def install(app: App) -> None:
    """One puppet at the origin facing the camera side (+Z)."""
    app.add_plugin(install_puppets)
    spawn_puppet(app.world, (0.0, 0.0, 0.0), 0.0, extra=(Appearance(color=(0.85, 0.35, 0.25)),))


def camera() -> OrbitCamera:
    """A three-quarter view of the field."""
    return OrbitCamera(target=[0.0, 0.8, 0.0], yaw=0.5, pitch=0.35, distance=6.0)


GAME = Game(name="sandbox", install=install, draw=draw_world, camera=camera)
