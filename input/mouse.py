"""The mouse as a MotionStick held at the camera (the default source).

The game loop hands pygame events to :meth:`MouseSource.handle_event` on the main
thread (pygame delivers events there). Each event becomes a ``"world"`` sample
whose pivot is the camera's eye and whose orientation points along the ray under
the cursor, with the drag plane's normal; so the simulation (and a replay) never
needs the camera:

- left press grabs what is under the cursor, drag moves it in the plane at the
  grab depth, release lets go. With ``plane="ground"`` (the default, what a game
  wants) the plane is horizontal at the grab point, so dragging walks the puppet
  over the ground and the grab depth is measured downwards from the camera; with
  ``plane="view"`` it faces the camera (a modelling tool's drag);
- the wheel changes the grab depth (``wheel_step`` metres per notch): in the ground
  plane, wheel up lifts what is held and wheel down lowers it (a puppet crouches);
- a quick upward stroke is a flick (jumps): the cursor rises at least ``flick_rise``
  screen heights within ``flick_window`` seconds of event time. Judged over a window,
  not between two events: events queued during a frame are handled in a burst, and a
  slow drag's one-pixel steps handled a millisecond apart looked like flicks. During
  the stroke the stick keeps pointing where it began (a gesture, not a drag);
- right-drag orbits the camera: camera-only, so it is left to the game loop
  (``handle_event`` returns ``False`` for it).

The camera is anything with ``forward`` and ``ray(px, py, width, height) ->
(origin, direction)`` (``engine.camera.OrbitCamera``).
"""

from __future__ import annotations

import time
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from engine import quat
from input.sample import PoseSample
from input.source import PoseSource

__all__ = ["MouseSource", "RayCamera"]

MOUSEMOTION, MOUSEBUTTONDOWN, MOUSEBUTTONUP, MOUSEWHEEL = 1024, 1025, 1026, 1027


class RayCamera(Protocol):
    """What the mouse needs from a camera."""

    @property
    def forward(self) -> Any: ...

    def ray(self, px: float, py: float, width: int, height: int) -> tuple[Any, Any]: ...


class MouseSource(PoseSource):
    """Mouse events → pose samples (fed from the main thread; no device thread).

    Args:
        wheel_step: metres of grab depth per wheel notch.
        flick_rise: how far the cursor must rise (screen heights) within ``flick_window``
            seconds to flick; an ordinary hand's flick rises 80–250 px in well under 0.15 s.
        flick_window: the longest stroke, in seconds, that still counts as one flick.
    """

    threaded = False
    person = True

    def __init__(
        self, wheel_step: float = 0.1, flick_rise: float = 0.08, flick_window: float = 0.15, plane: str = "ground"
    ) -> None:
        super().__init__("mouse")
        if plane not in ("ground", "view"):
            raise ValueError(f"plane must be 'ground' or 'view', not {plane!r}")
        self.plane = plane
        if not (flick_rise > 0 and flick_window > 0):
            raise ValueError("flick_rise and flick_window must be positive")
        self.wheel_step = wheel_step
        self.flick_rise, self.flick_window = flick_rise, flick_window
        self.pressed = False
        self._last: tuple[float, float, float] | None = None  # x, y, time
        self._trail: list[tuple[float, float, float]] = []  # (time, x, y) of the held drag, within the window
        self._flicked = False
        self._status.connected = True

    def handle_event(self, event: Any, camera: RayCamera, size: tuple[int, int], now: float | None = None) -> bool:
        """Turn one pygame event into a sample; ``True`` if the event was the stick's."""
        now = time.monotonic() if now is None else now
        kind = event.type
        if kind == MOUSEWHEEL:
            pos = self._last[:2] if self._last else (size[0] / 2, size[1] / 2)
            self._emit(camera, size, pos, now, depth_delta=-float(event.y) * self.wheel_step)
            return True
        if kind in (MOUSEBUTTONDOWN, MOUSEBUTTONUP) and getattr(event, "button", 1) != 1:
            return False  # right button: camera orbit (game loop); wheel buttons 4/5 come as MOUSEWHEEL
        if kind == MOUSEBUTTONDOWN:
            self.pressed, self._flicked = True, False
            self._last = (*event.pos, now)
            self._trail = [(now, float(event.pos[0]), float(event.pos[1]))]
            self._emit(camera, size, event.pos, now, touch=True)
            return True
        if kind == MOUSEBUTTONUP:
            self.pressed = False
            self._emit(camera, size, event.pos, now, touch=False)
            self._last = (*event.pos, now)
            return True
        if kind == MOUSEMOTION:
            if getattr(event, "buttons", (0, 0, 0))[2] and not self.pressed:
                return False  # right-drag: orbiting
            flick, aim = self._stroke(event.pos, now, size[1]) if self.pressed else (False, event.pos)
            self._last = (*event.pos, now)
            self._emit(camera, size, aim, now, flick=flick)
            return True
        return False

    def _stroke(self, pos: tuple[float, float], now: float, height: int) -> tuple[bool, tuple[float, float]]:
        """Judge the held cursor, now at ``pos``: ``(flick, where the stick should point)``.

        The rise is measured from the lowest point of the last ``flick_window`` seconds;
        one flick per stroke: the next needs the cursor to come back down first. While a
        fast upward stroke is under way (half a flick's rise within the window) and until
        the cursor has come back down, the stick keeps pointing where the stroke began:
        the stroke says "jump", not "drag the puppet metres toward the horizon" (near the
        horizon a hundred pixels are metres of ground, past the drag limit)."""
        start = now - self.flick_window
        older = [p for p in self._trail if p[0] < start]
        # Where the cursor rested when the window began counts too: a flick's first move after
        # a pause must rise from the resting point, or it lifts the puppet off its feet before
        # the second move is judged a flick (and a puppet in the air does not jump).
        rested = [(start, older[-1][1], older[-1][2])] if older else []
        self._trail = rested + [p for p in self._trail if p[0] >= start] + [(now, float(pos[0]), float(pos[1]))]
        base = max(self._trail, key=lambda p: p[2])
        rise = (base[2] - float(pos[1])) / height
        flick = rise >= self.flick_rise and not self._flicked
        if flick:
            self._flicked = True
        elif rise <= 0.25 * self.flick_rise:
            self._flicked = False
        stroking = self._flicked or rise >= 0.5 * self.flick_rise
        return flick, ((base[1], base[2]) if stroking else (float(pos[0]), float(pos[1])))

    def _plane_normal(self, camera: RayCamera) -> NDArray[np.float64]:
        if self.plane == "ground":
            return np.array([0.0, -1.0, 0.0])
        return np.asarray(camera.forward, dtype=np.float64)

    def _emit(
        self,
        camera: RayCamera,
        size: tuple[int, int],
        pos: Any,
        now: float,
        touch: bool | None = None,
        depth_delta: float = 0.0,
        flick: bool = False,
    ) -> None:
        origin, direction = camera.ray(float(pos[0]), float(pos[1]), int(size[0]), int(size[1]))
        d = np.asarray(direction, dtype=np.float64)
        orientation = quat.between([0.0, 0.0, 1.0], d / np.linalg.norm(d))
        self.push(
            PoseSample(
                time=now,
                source="mouse",
                orientation=orientation,
                position=np.asarray(origin, float),
                touch=touch,
                mode="world",
                plane_normal=self._plane_normal(camera),
                depth_delta=depth_delta,
                flick=flick,
            )
        )
