"""Snow physics of the game rules: how a rolled ball grows, and the marks it leaves.

A ball rolled over fresh snow of depth ``d`` sinks into it and peels up the strip
under it. The strip's cross-section is the circular segment the ball cuts into
the snow layer, ``A = r²·acos((r−d)/r) − (r−d)·√(2rd − d²)``; rolling ``ds`` adds
``A·ds`` of snow to the ball, so ``r`` grows by volume, ``(4/3)π·r³ += A·ds``. The
snow taken comes out of the field (a coarse grid of snow depth): a strip rolled
again gives less, and the bare strips are the marks drawn in the snow.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

__all__ = ["segment_area", "grow_radius", "SnowField"]


def segment_area(radius: float, depth: float) -> float:
    """Cross-section of snow a ball of ``radius`` peels from a layer ``depth`` deep."""
    d = min(max(depth, 0.0), radius)
    if d <= 0.0:
        return 0.0
    h = radius - d
    return float(radius**2 * np.arccos(h / radius) - h * np.sqrt(max(2 * radius * d - d * d, 0.0)))


def grow_radius(radius: float, distance: float, depth: float) -> float:
    """Radius after rolling ``distance`` metres over snow ``depth`` deep (volume conserved)."""
    volume = 4.0 / 3.0 * np.pi * radius**3 + segment_area(radius, depth) * max(distance, 0.0)
    return float(np.cbrt(volume * 3.0 / (4.0 * np.pi)))


@dataclass
class SnowField:
    """Snow depth on a square grid centred on the origin; rolled strips are cleared.

    Attributes:
        size: side length of the field in metres.
        cell: grid cell size in metres.
        depth: ``[N,N]`` snow depth per cell in metres.
    """

    size: float = 24.0
    cell: float = 0.1
    initial_depth: float = 0.04
    depth: NDArray[np.float64] = field(init=False)  # ``initial_depth`` everywhere, made by __post_init__

    SIM_STATE = True

    def __post_init__(self) -> None:
        n = int(round(self.size / self.cell))
        self.depth = np.full((n, n), self.initial_depth)

    def _cells(self, center: NDArray[np.float64], half_width: float) -> tuple[slice, slice]:
        n = self.depth.shape[0]
        lo = np.floor((center[[0, 2]] - half_width + self.size / 2) / self.cell).astype(int)
        hi = np.ceil((center[[0, 2]] + half_width + self.size / 2) / self.cell).astype(int)
        lo, hi = np.clip(lo, 0, n), np.clip(hi, 0, n)
        return slice(lo[0], hi[0]), slice(lo[1], hi[1])

    def depth_at(self, position: NDArray[np.float64]) -> float:
        """Snow depth under a point (0 off the field)."""
        n = self.depth.shape[0]
        i, k = np.floor((np.asarray(position)[[0, 2]] + self.size / 2) / self.cell).astype(int)
        return float(self.depth[i, k]) if 0 <= i < n and 0 <= k < n else 0.0

    def roll(self, start: NDArray[np.float64], end: NDArray[np.float64], radius: float) -> float:
        """Roll a ball from ``start`` to ``end``: take the snow it peels up; return its new radius.

        The snow taken, ``A·ds``, is removed from the cells under the strip in
        proportion, so volume is conserved whatever the step size: a ball moved a
        centimetre per step peels a cell as surely as one moved across it at once.
        """
        start, end = np.asarray(start, dtype=np.float64), np.asarray(end, dtype=np.float64)
        distance = float(np.linalg.norm((end - start)[[0, 2]]))
        if distance <= 0.0:
            return radius
        steps = max(1, int(np.ceil(distance / (0.5 * self.cell))))
        ds = distance / steps
        r = radius
        for k in range(steps):
            p = start + (end - start) * (k + 0.5) / steps
            d_here = self.depth_at(p)
            if d_here <= 0.0:
                continue
            sunk = min(d_here, r)
            half = max(np.sqrt(max(2 * r * sunk - sunk * sunk, 0.0)), 0.5 * self.cell)
            cells = self._cells(p, half)
            patch = self.depth[cells]
            if patch.size == 0:
                continue
            mean_depth = float(patch.mean())
            taken = segment_area(r, mean_depth) * ds
            patch -= min(taken / (patch.size * self.cell**2), mean_depth) * (patch > 0)
            np.maximum(patch, 0.0, out=patch)
            self.depth[cells] = patch
            r = float(np.cbrt(r**3 + 3.0 * taken / (4.0 * np.pi)))
        return r
