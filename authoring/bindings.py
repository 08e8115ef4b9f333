"""Window events → operations: the one key and pointer mapping of every session (games and tools).

The same bindings everywhere (README, "Controls"):

- **left button** acts: press, drag, release — a tool gets :class:`~authoring.operations.Press`,
  :class:`~authoring.operations.Move` and :class:`~authoring.operations.Release` (Shift held: the
  tool's alternative action); a game's mouse source gets the events and moves the stick;
- **right-drag** orbits the camera (:class:`~authoring.operations.Orbit`, :func:`orbit_camera`);
- **wheel** zooms in a tool (:class:`~authoring.operations.Zoom`) and crouches in a game (the
  mouse source's depth);
- **keys** go to the session as :class:`~authoring.operations.Key` unless the session does not
  want them; **Esc** always stays the runner's (quit), and so do keys a session leaves (P pauses).

Pointer moves and orbit drags are merged to one operation per step (the latest position,
the summed drag), so a recording holds one pointer operation per step, not one per event.
"""

from __future__ import annotations

from typing import Any

from authoring.operations import Key, Move, Operation, Orbit, Press, Release, Resize, Zoom
from engine.camera import OrbitCamera

__all__ = ["ACT", "ORBIT_BUTTON", "ORBIT_RADIANS_PER_PIXEL", "ZOOM_STEP", "Bindings", "orbit_camera"]

#: Radians the camera turns per pixel of right-drag, in yaw and pitch.
ORBIT_RADIANS_PER_PIXEL = 0.005
#: Distance factor of one wheel notch away from the scene (its inverse: towards).
ZOOM_STEP = 1.1
ACT, ORBIT_BUTTON = 1, 3


def orbit_camera(camera: OrbitCamera, op: Orbit) -> None:
    """Turn ``camera`` by a right-drag: right turns the view right, down tilts it down (every session alike)."""
    camera.orbit(-ORBIT_RADIANS_PER_PIXEL * op.dx, -ORBIT_RADIANS_PER_PIXEL * op.dy)


class Bindings:
    """Turns pygame events into operations, queued until :meth:`take` (once per step).

    ``pointer_acts=False`` (a game) leaves left-button and wheel events to the input
    sources (the mouse source turns them into stick samples): :meth:`feed` returns ``None``
    for them and the caller hands the event on.
    """

    def __init__(self, pointer_acts: bool = True) -> None:
        self.pointer_acts = pointer_acts
        self.orbiting = False
        self._queue: list[Operation] = []
        self._pending: Move | Orbit | None = None

    def operation(self, ev: Any, size: tuple[int, int]) -> Operation | None:
        """The operation an event makes (``None``: not one of the session's; button state is kept)."""
        import pygame

        kind = ev.type
        if kind == pygame.MOUSEBUTTONDOWN and ev.button == ORBIT_BUTTON:
            self.orbiting = True
        elif kind == pygame.MOUSEBUTTONUP and ev.button == ORBIT_BUTTON:
            self.orbiting = False
        elif kind == pygame.MOUSEMOTION and self.orbiting:
            return Orbit(float(ev.rel[0]), float(ev.rel[1]))
        elif not self.pointer_acts and kind in (
            pygame.MOUSEBUTTONDOWN,
            pygame.MOUSEBUTTONUP,
            pygame.MOUSEMOTION,
            pygame.MOUSEWHEEL,
        ):
            return None
        elif kind == pygame.MOUSEBUTTONDOWN and ev.button == ACT:
            return Press(float(ev.pos[0]), float(ev.pos[1]), _shift(ev))
        elif kind == pygame.MOUSEBUTTONUP and ev.button == ACT:
            return Release(float(ev.pos[0]), float(ev.pos[1]))
        elif kind == pygame.MOUSEMOTION:
            return Move(float(ev.pos[0]), float(ev.pos[1]))
        elif kind == pygame.MOUSEWHEEL and ev.y:
            return Zoom(1.0 / ZOOM_STEP if ev.y > 0 else ZOOM_STEP)
        elif kind in (pygame.VIDEORESIZE, pygame.WINDOWSIZECHANGED):
            return Resize(int(size[0]), int(size[1]))
        elif kind == pygame.KEYDOWN and ev.key != pygame.K_ESCAPE:
            mod = getattr(ev, "mod", 0)  # (a posted event may carry no modifiers)
            return Key(pygame.key.name(ev.key), bool(mod & pygame.KMOD_CTRL), bool(mod & pygame.KMOD_SHIFT))
        return None

    def queue(self, op: Operation) -> None:
        """Queue an operation for the next step, merging pointer moves and orbit drags."""
        if isinstance(op, Orbit) and isinstance(self._pending, Orbit):
            self._pending = Orbit(self._pending.dx + op.dx, self._pending.dy + op.dy)
        elif isinstance(op, (Move, Orbit)):
            if self._pending is not None and type(self._pending) is not type(op):
                self._queue.append(self._pending)
            self._pending = op
        else:
            if self._pending is not None:
                self._queue.append(self._pending)
                self._pending = None
            self._queue.append(op)

    def take(self) -> list[Operation]:
        """The operations queued since the last call, in order."""
        if self._pending is not None:
            self._queue.append(self._pending)
            self._pending = None
        out, self._queue = self._queue, []
        return out


def _shift(ev: Any) -> bool:
    import pygame

    try:
        return bool(pygame.key.get_mods() & pygame.KMOD_SHIFT)
    except pygame.error:  # no display initialised (a scripted or headless session): no modifier held
        return False
