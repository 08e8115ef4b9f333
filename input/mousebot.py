"""A scripted mouse: drives a game through the real mouse input path, for demos and tests.

The bot turns world-space intentions ("press on this entity", "drag the held thing
to that point over two seconds", "three wheel notches down") into the pygame events
a person's mouse would produce, feeds them to the game's
:class:`input.mouse.MouseSource` exactly as the game loop does, and steps the app one
fixed step at a time. Recorded with :class:`input.recording.Recorder`, the result is
an ordinary recording: replaying it exercises nothing the bot wrote.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pygame

from engine.app import App
from engine.camera import Camera
from engine.components import Grabbable, Stick, Transform
from engine.ecs import Entity
from input.motionstick import StickState
from input.mouse import MouseSource

__all__ = ["MouseBot"]


class MouseBot:
    """Drives ``app`` with synthetic mouse events seen through ``camera`` at ``size`` pixels."""

    def __init__(self, app: App, mouse: MouseSource, camera: Camera, size: tuple[int, int] = (1280, 720)) -> None:
        self.app, self.mouse, self.camera, self.size = app, mouse, camera, size
        self.pos = (size[0] / 2.0, size[1] / 2.0)
        self.on_step: list[Callable[[App], None]] = []

    @property
    def now(self) -> float:
        """Event time: the simulation clock (the bot never reads the wall clock)."""
        return self.app.world.frame * self.app.world.dt

    def _send(self, kind: int, **attrs: object) -> None:
        self.mouse.handle_event(pygame.event.Event(kind, attrs), self.camera, self.size, now=self.now)

    def step(self, n: int = 1) -> None:
        """Run ``n`` fixed steps."""
        for _ in range(n):
            self.app.step()
            for cb in self.on_step:
                cb(self.app)

    def wait(self, seconds: float) -> None:
        """Do nothing for a while (the simulation keeps running)."""
        self.step(max(1, int(round(seconds / self.app.world.dt))))

    def pixel(self, point: np.ndarray) -> tuple[float, float]:
        """Where a world point appears on screen."""
        px = self.camera.project(np.asarray(point, dtype=np.float64)[None], *self.size)[0]
        return float(px[0]), float(px[1])

    def move_to_pixel(self, px: tuple[float, float], buttons: tuple[int, int, int]) -> None:
        """One motion event to ``px``."""
        rel = (int(round(px[0] - self.pos[0])), int(round(px[1] - self.pos[1])))
        self.pos = px
        self._send(pygame.MOUSEMOTION, pos=(px[0], px[1]), rel=rel, buttons=buttons)

    def anchor(self, entity: Entity) -> np.ndarray:
        """The point the stick would hold on ``entity``."""
        tr = self.app.world.get(entity, Transform)
        grab = self.app.world.try_get(entity, Grabbable)
        return tr.position.copy() if grab is None else grab.anchor(tr)

    def press_on(self, entity: Entity) -> None:
        """Hover over ``entity`` and press the left button; raises if something else was grabbed
        (a script that goes on holding the wrong thing records nonsense)."""
        self.move_to_pixel(self.pixel(self.anchor(entity)), (0, 0, 0))
        self.step()
        self._send(pygame.MOUSEBUTTONDOWN, pos=self.pos, button=1)
        self.step()
        grabbed = [stick.grabbed for _, stick, _ in self.app.world.query(Stick, StickState)]
        if entity not in grabbed:
            raise RuntimeError(f"pressed on entity {entity} but the stick holds {grabbed} (hidden behind something?)")

    def release(self) -> None:
        """Let go of the left button."""
        self._send(pygame.MOUSEBUTTONUP, pos=self.pos, button=1)
        self.step()

    def wheel(self, notches: int) -> None:
        """Turn the wheel (positive = up, lifts in the ground plane), one notch per step."""
        for _ in range(abs(notches)):
            self._send(pygame.MOUSEWHEEL, x=0, y=int(np.sign(notches)))
            self.step()

    def held_height(self) -> float:
        """Height of the plane the held thing moves in (the stick tip's height)."""
        for _, stick, _ in self.app.world.query(Stick, StickState):
            return float(stick.tip[1])
        raise RuntimeError("no stick")

    def drag_to(self, point: np.ndarray, seconds: float) -> None:
        """Drag the held thing (button down) in a straight line to above ``point`` (x, z used)."""
        steps = max(1, int(round(seconds / self.app.world.dt)))
        start = self.tip()
        goal = np.array([point[0], start[1], point[2]])
        for k in range(1, steps + 1):
            p = start + (goal - start) * k / steps
            p[1] = self.held_height()
            self.move_to_pixel(self.pixel(p), (1, 0, 0))
            self.step()

    def drag_path(self, points: list[np.ndarray], speed: float) -> None:
        """Drag through ``points`` at ``speed`` m/s."""
        for p in points:
            dist = float(np.linalg.norm((np.asarray(p) - self.tip())[[0, 2]]))
            self.drag_to(np.asarray(p), max(dist / speed, self.app.world.dt))

    def flick(self) -> None:
        """A quick upward flick of the mouse while holding (a jump)."""
        for _ in range(4):
            self.move_to_pixel((self.pos[0], self.pos[1] - 0.06 * self.size[1]), (1, 0, 0))
            self.step()
        for _ in range(4):
            self.move_to_pixel((self.pos[0], self.pos[1] + 0.06 * self.size[1]), (1, 0, 0))
            self.step()

    def tip(self) -> np.ndarray:
        """The stick tip now."""
        for _, stick, _ in self.app.world.query(Stick, StickState):
            return stick.tip.copy()
        raise RuntimeError("no stick")
