"""Drawing quality levels, and the governor that picks one from the measured frame time.

On a software rasteriser (llvmpipe, a laptop without a GPU) a frame's cost is almost all
fragment work, so the lever that matters is how many pixels are shaded: ``low`` and
``medium`` draw the 3-D scene into a smaller buffer and scale it up (the overlay text is
drawn at full size afterwards, so it stays sharp). Each level also bounds the shadow
work (map and mask sizes) and how coarse a round solid may be drawn (silhouette error).
``high`` adds the per-pixel snow detail near the camera; ``low`` lets only the solids
nearest the camera cast shadows (600 of them: a crowd's near rows), bounding the shadow
work whatever the crowd's size, and draws capsules and spheres as ray-cast impostors
(a quad of 4 vertices each: a crowd is vertex-bound on a software rasteriser).

``auto`` is :class:`QualityGovernor`: it starts at ``medium``, steps down as soon as the
median of the last frames misses the 30 fps budget (or sooner, after :data:`QUICK` frames, when
every one of them took over twice the budget: a thousand puppets at ``medium`` drew 3 fps, and
twelve such frames were four seconds of slow motion at the start of play), and steps up only when a level's
frames would still fit with room to spare at the level above (estimated by the ratio of
the shaded pixels), never back to a level it has left for being too slow. It is display
only: the simulation never sees the quality.

A frame's cost is judged in two parts: the drawing, which the level changes, and the
simulation steps a frame at the budget's rate must run (two 60 Hz steps at 30 fps), which
no level changes. The window's whole loop time is not used: how many steps a frame runs
grows as the frame rate falls (four at 15 fps), so it would count the simulation twice
over in a slow window, and the pixel ratio of a step up would be applied to the
simulation's share too, keeping a cheap drawing at ``low`` for good.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import numpy as np

__all__ = ["Quality", "QUALITIES", "QUALITY_NAMES", "QUICK", "QualityGovernor", "parse_quality"]

QUICK = 4
"""Frames after which a level whose last four frames each took over twice the budget is left, without
waiting for the governor's whole window (the first frames at a level compile shaders: one or two slow
ones must not decide; and a quick one, the window's first frame with nothing stepped yet, must not
hold the level for the whole window: it did, for 12 frames of 0.3 s)."""


@dataclass(frozen=True)
class Quality:
    """One level: the fraction of the pixels shaded, the shadow resolutions, the detail allowed."""

    name: str
    scale: float
    """Side of the 3-D drawing buffer as a fraction of the window's (text is always full size)."""
    shadow_map: int
    shadow_mask: int
    silhouette_px: float
    """Largest outline error a round solid's mesh may have, in (full-size) pixels."""
    ground_detail: bool
    """Per-pixel snow drifts and sparkle near the camera (else the snow is shaded per vertex)."""
    max_casters: int | None = None
    """Capsules and spheres drawn into the shadow map, nearest the camera first (``None``: all).
    A crowd is vertex-bound on a software rasteriser, and the shadow map draws it a second time."""
    impostors: bool = False
    """Capsules and spheres ray-cast on a quad over their outline (:mod:`engine.render.impostors`), not meshed."""


QUALITIES = {
    "low": Quality("low", 0.5, 512, 128, 2.0, False, max_casters=600, impostors=True),
    "medium": Quality("medium", 0.75, 1024, 256, 1.0, False),
    "high": Quality("high", 1.0, 1024, 256, 1.0, True),
}
QUALITY_NAMES = ("low", "medium", "high", "auto")


def parse_quality(text: str) -> str:
    """``text`` as a quality name (``ValueError`` naming the choices otherwise)."""
    name = text.strip().lower()
    if name not in QUALITY_NAMES:
        raise ValueError(f"quality must be one of {', '.join(QUALITY_NAMES)}, not {text!r}")
    return name


class QualityGovernor:
    """Chooses the level from frame durations (seconds) while ``auto``; fixed otherwise.

    Args:
        mode: ``low``, ``medium``, ``high`` or ``auto``.
        budget: the frame time to stay under (1/30 s).
        window: frames per decision (the median of these).
    """

    ORDER = ("low", "medium", "high")

    def __init__(self, mode: str = "auto", budget: float = 1.0 / 30.0, window: int = 12) -> None:
        self.mode = parse_quality(mode)
        self.budget, self.window = budget, window
        self.level = "medium" if self.mode == "auto" else self.mode
        self._times: deque[float] = deque(maxlen=window)
        self._fixed: deque[float] = deque(maxlen=window)
        self._too_slow: set[str] = set()

    @property
    def quality(self) -> Quality:
        """The level to draw the next frame at."""
        return QUALITIES[self.level]

    def cycle(self) -> str:
        """Next mode in ``low → medium → high → auto`` (the quality key); returns it."""
        self.mode = QUALITY_NAMES[(QUALITY_NAMES.index(self.mode) + 1) % len(QUALITY_NAMES)]
        self._times.clear()
        self._fixed.clear()
        self._too_slow.clear()
        if self.mode != "auto":
            self.level = self.mode
        return self.mode

    def frame(self, seconds: float, fixed: float = 0.0) -> bool:
        """Record one frame: ``seconds`` of drawing at the current level, and ``fixed`` seconds that
        a frame at the budget's rate spends on what no level changes (the simulation steps); true
        when the level changed."""
        if self.mode != "auto":
            return False
        self._times.append(seconds)
        self._fixed.append(fixed)
        i = self.ORDER.index(self.level)
        if len(self._times) < self.window:
            recent = np.add(self._times, self._fixed)[-QUICK:]  # the last few: a quick first frame must not hold it
            far_over = len(recent) == QUICK and recent.min() > 2.0 * self.budget
            if far_over and i > 0:
                self._too_slow.add(self.level)
                return self._set(self.ORDER[i - 1])
            return False
        drawing, rest = float(np.median(self._times)), float(np.median(self._fixed))
        if drawing + rest > self.budget and i > 0:
            self._too_slow.add(self.level)
            return self._set(self.ORDER[i - 1])
        if i + 1 < len(self.ORDER):
            up = self.ORDER[i + 1]
            grow = (QUALITIES[up].scale / QUALITIES[self.level].scale) ** 2
            if up not in self._too_slow and drawing * grow + rest < 0.8 * self.budget:
                return self._set(up)
        return False

    def _set(self, level: str) -> bool:
        self.level = level
        self._times.clear()
        self._fixed.clear()
        return True
