"""Falling snow described once, placed by the clock: the same flakes on every screen that draws them.

A :class:`Snowfall` is a fixed set of flakes (start positions and sway phases, from a
game's fixed seed) and the rule that moves them with the time: they fall at ``speed``
and wrap round from the ground to ``height``, swaying ``sway`` metres on two slow
sines. The desktop draws it with :meth:`Snowfall.draw`; a phone gets the description
once (the scene GLB, :mod:`input.web.scene_glb`) and moves the flakes itself from the
step it shows, so 900 moving points cost nothing on the wire. Drawn only: it never
touches the simulation.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from engine.render.scene import RenderScene

__all__ = ["Snowfall"]


@dataclass(frozen=True)
class Snowfall:
    """Flakes starting at ``start [N, 3]`` with sway phases ``phase [N]`` (see the module docstring)."""

    start: NDArray[np.float64]
    phase: NDArray[np.float64]
    speed: float = 0.6
    height: float = 9.0
    sway: float = 0.25
    sway_rates: tuple[float, float] = (0.7, 0.5)
    size: float = 0.035
    color: tuple[float, float, float] = (1.0, 1.0, 1.0)

    def positions(self, time: float) -> NDArray[np.float64]:
        """Every flake's position at ``time`` (seconds of simulated time)."""
        p = self.start.copy()
        p[:, 1] = (p[:, 1] - self.speed * time) % self.height
        p[:, 0] += self.sway * np.sin(self.sway_rates[0] * time + self.phase)
        p[:, 2] += self.sway * np.cos(self.sway_rates[1] * time + self.phase)
        return p

    def draw(self, scene: RenderScene, time: float) -> None:
        """The flakes at ``time`` as round points in ``scene``."""
        scene.add_points(self.positions(time), size=self.size, color=self.color)
