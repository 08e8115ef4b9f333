"""The jump arc of thesis §6.3: a side-view parabola refitted every frame, and its validity.

Seen from the side (``x`` = distance travelled along the take-off direction, ``y`` =
height) the stick's path is fitted each frame by the parabola through the start
point ``(x0, y0)`` and the current point ``(xt, yt)`` with the current slope ``y't``
(Eq. 6.3). Writing ``Δx = xt − x0`` and ``Δy = yt − y0``::

    a = (y't·Δx − Δy) / Δx²
    b = y't − 2·a·xt = (y't·(x0² − xt²) + 2·xt·Δy) / Δx²
    c = y0 − a·x0² − b·x0

(the thesis prints ``b`` with ``− 2·xt·Δy``; differentiating ``y`` at ``xt`` gives the
``+`` used here, which is the one that satisfies ``y'(xt) = y't``). The apex
``(−b/2a, y(−b/2a))`` drives the jump animation.

A jump is *invalid* — and the puppet becomes a ragdoll — when (1) it rises again after
starting the descent, (2) it turns in the air, (3) it stops in the air, or (4) the stick
is pulled down hard. Each is judged against the motion the jump already has, with
these tolerances (fields of :class:`JumpTracker`):

- *rising again*: the stick climbs faster than ``rise_threshold`` (0.35 m/s) after it
  fell faster than that;
- *turning*, when the stick's own path is the arc (a phone lifted): its ground velocity
  leaves the take-off direction by more than ``turn_limit_deg`` (40°) while faster than
  ``stop_speed``. A running puppet's stick moves forward: that is the take-off direction,
  not a turn. When a flick launched the puppet (the mouse, whose stick stays in its
  plane), the stick *leads*: it turns the jump when its ground point strays more than
  ``turn_offset`` (0.6 m) from the jump's line for ``turn_time`` (0.3 s) —
  :meth:`JumpTracker.lead`. A flick's own stroke comes back within that time even when a
  slow machine draws at 10 frames a second (its events then arrive in bursts, several
  steps apart), and a hand that holds still or follows the jump stays on the line;
- *stopping*: slower than ``stop_speed`` (0.25 m/s) in every direction for ``stop_time``
  (0.15 s) while more than 0.15 m up;
- *pulling down*: the stick falls faster than ``slam_speed`` (6 m/s), beyond any fall
  from a jump's height.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

__all__ = ["Parabola", "fit_parabola", "JumpTracker", "JumpStatus"]


@dataclass(frozen=True)
class Parabola:
    """``y = a·x² + b·x + c`` in the jump's side view."""

    a: float
    b: float
    c: float

    def __call__(self, x: float) -> float:
        return self.a * x * x + self.b * x + self.c

    @property
    def apex(self) -> tuple[float, float] | None:
        """The top of the arc, or ``None`` for an arc that opens upwards or is a line."""
        if self.a >= -1e-9:
            return None
        x = -self.b / (2 * self.a)
        return x, self(x)


def fit_parabola(x0: float, y0: float, xt: float, yt: float, slope: float) -> Parabola | None:
    """Eq. 6.3: the parabola through ``(x0,y0)`` and ``(xt,yt)`` with slope ``slope`` at ``xt``."""
    dx = xt - x0
    if abs(dx) < 1e-6:
        return None
    a = (slope * dx - (yt - y0)) / dx**2
    b = slope - 2 * a * xt
    c = y0 - a * x0**2 - b * x0
    return Parabola(a, b, c)


class JumpStatus(enum.Enum):
    """What the tracker concluded this frame."""

    RISING = "rising"
    FALLING = "falling"
    LANDED = "landed"
    ROSE_AGAIN = "rose again after starting to fall"
    TURNED = "turned in the air"
    STOPPED = "stopped in the air"
    PULLED_DOWN = "pulled down hard"


@dataclass
class JumpTracker:
    """Follows one jump of the stick tip from take-off to landing (a component field)."""

    start: NDArray[np.float64]
    direction: NDArray[np.float64]
    ground: float = 0.0
    rise_threshold: float = 0.35
    turn_limit_deg: float = 40.0
    stop_speed: float = 0.25
    stop_time: float = 0.15
    slam_speed: float = 6.0
    turn_offset: float = 0.6
    turn_time: float = 0.3
    descending: bool = False
    off_line_for: float = 0.0
    lead_origin: NDArray[np.float64] | None = None
    stopped_for: float = 0.0
    peak: float = field(default=-np.inf)
    apex: NDArray[np.float64] = field(default_factory=lambda: np.full(2, np.nan))

    @classmethod
    def start_at(cls, point: NDArray[np.float64], velocity: NDArray[np.float64], ground: float = 0.0) -> JumpTracker:
        """Begin tracking at take-off: the direction is the horizontal part of the velocity."""
        horizontal = np.array([velocity[0], velocity[2]], dtype=np.float64)
        n = np.linalg.norm(horizontal)
        direction = horizontal / n if n > 1e-6 else np.zeros(2)
        return cls(start=np.array(point, dtype=np.float64), direction=direction, ground=ground)

    def side_view(self, point: NDArray[np.float64]) -> tuple[float, float]:
        """``(x, y)`` of a world point: distance along the take-off direction, height."""
        d = np.asarray(point, dtype=np.float64) - self.start
        return float(d[0] * self.direction[0] + d[2] * self.direction[1]), float(point[1])

    def lead(self, stick_point: NDArray[np.float64], dt: float) -> JumpStatus | None:
        """Judge a launched jump's leading stick (its ground point this step): ``TURNED`` once it
        has stayed more than ``turn_offset`` off the jump's line for ``turn_time``."""
        ground = np.array([stick_point[0], stick_point[2]], dtype=np.float64)
        if self.lead_origin is None:
            self.lead_origin = ground
        offset = ground - self.lead_origin
        lateral = offset - float(offset @ self.direction) * self.direction
        if float(np.linalg.norm(lateral)) > self.turn_offset:
            self.off_line_for += dt
            if self.off_line_for >= self.turn_time:
                return JumpStatus.TURNED
        else:
            self.off_line_for = 0.0
        return None

    def update(
        self, point: NDArray[np.float64], velocity: NDArray[np.float64], dt: float, height_above_ground: float
    ) -> JumpStatus:
        """Take one frame of the stick tip; returns the jump's status."""
        vy = float(velocity[1])
        horizontal = np.array([velocity[0], velocity[2]])
        speed_h = float(np.linalg.norm(horizontal))
        self.peak = max(self.peak, float(point[1]))
        if self.descending and vy > self.rise_threshold:
            return JumpStatus.ROSE_AGAIN
        if vy < -self.slam_speed:
            return JumpStatus.PULLED_DOWN
        if vy < -self.rise_threshold:
            self.descending = True
        if np.any(self.direction) and speed_h > self.stop_speed:
            cos = float(np.dot(horizontal / speed_h, self.direction))
            if np.degrees(np.arccos(np.clip(cos, -1, 1))) > self.turn_limit_deg:
                return JumpStatus.TURNED
        if speed_h < self.stop_speed and abs(vy) < self.stop_speed and height_above_ground > 0.15:
            self.stopped_for += dt
            if self.stopped_for >= self.stop_time:
                return JumpStatus.STOPPED
        else:
            self.stopped_for = 0.0
        x0, y0 = 0.0, float(self.start[1])
        xt, yt = self.side_view(point)
        slope = vy / speed_h if speed_h > 1e-6 else np.inf
        if np.isfinite(slope):
            arc = fit_parabola(x0, y0, xt, yt, slope)
            top = arc.apex if arc is not None else None
            if top is not None:
                self.apex = np.array(top)
        if self.descending and height_above_ground <= 0.02:
            return JumpStatus.LANDED
        return JumpStatus.FALLING if self.descending else JumpStatus.RISING
