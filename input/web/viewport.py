"""The phone is the viewport: after every step, the game's drawing goes to the phones that watch.

:class:`PhoneViewport` hangs on ``App.on_step_end``. When at least one page is
connected it draws the world once into a scratch :class:`RenderScene` (the game's own
state drawing: puppets, props, snowmen, sticks, scenery, the snowman's tracks and
footprints; the falling snow is left out, see :attr:`games.base.Game.draw_state`, and
described once instead: :attr:`games.base.Game.snowfall`),
quantises it (:func:`input.web.scene_stream.quantise`) with the camera the phone is
(the held controller's view, :func:`input.controller_view.controller_camera`, or the
game's starting camera before the first reading) and hands it to the
:class:`~input.web.server.WebSource`, whose connections each send it at their own pace.

It only reads the world: the drawing writes display-only components at most
(``Appearance``, not hashed), so a session with phones watching records and replays
exactly as one without.
"""

from __future__ import annotations

import time
from collections.abc import Callable

from engine import quat
from engine.camera import Camera
from engine.ecs import World
from engine.render.scene import RenderScene
from engine.render.snowfall import Snowfall
from input.controller_view import controller_camera
from input.web.scene_stream import CameraPose, quantise
from input.web.server import WebSource

__all__ = ["PhoneViewport", "camera_pose"]


def camera_pose(camera: Camera) -> CameraPose:
    """A camera's eye, orientation (camera → world) and vertical field of view."""
    x, y, z = (float(v) for v in camera.eye)
    w, qx, qy, qz = (float(v) for v in quat.from_matrix(camera.rotation))
    return CameraPose((x, y, z), (w, qx, qy, qz), float(camera.fov_y))


class PhoneViewport:
    """Publish the scene to ``source``'s pages after every step (see the module docstring).

    Args:
        source: the web source whose connected pages draw the scene.
        draw: the game's state drawing ``(world, scene, alpha)``.
        fallback: the camera used while no controller drives a stick.
        snowfall: the game's falling snow, which the page moves itself (in the GLB, once).
    """

    def __init__(
        self,
        source: WebSource,
        draw: Callable[[World, RenderScene, float], None],
        fallback: Callable[[], Camera],
        snowfall: Snowfall | None = None,
    ) -> None:
        self.source = source
        self.draw = draw
        self.fallback = fallback
        self.snowfall = snowfall
        self._scene = RenderScene()

    def __call__(self, world: World) -> None:
        """``on_step_end``: draw and publish, only when a page watches."""
        if not self.source.viewers:
            return
        scene = self._scene
        scene.clear()
        self.draw(world, scene, 1.0)
        camera = controller_camera(world) or self.fallback()
        state = quantise(scene, world.frame, time.time(), camera_pose(camera))
        self.source.publish(state, scene, self.snowfall, world.dt)
