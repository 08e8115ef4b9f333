"""The key timeline under the Motion Curves viewport: where each frame and key sits, and its picture.

A strip along the bottom of the window: one tick per frame, an orange diamond per key,
a yellow bar at the current frame. The layout is pure pixel arithmetic (the scene hit-tests
presses with it, the tests aim at it), and the picture is an RGBA overlay, so it looks the
same in a window and headless.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["Timeline", "KEY_RGB", "CURSOR_RGB"]

KEY_RGB = (245, 140, 25)
CURSOR_RGB = (255, 230, 25)
_STRIP_RGBA = (30, 32, 40, 210)
_TICK_RGB = (150, 155, 170)
PICK_KEY_PX = 9.0


@dataclass(frozen=True)
class Timeline:
    """The strip's layout in a window of ``size`` for a clip of ``frames`` frames."""

    size: tuple[int, int]
    frames: int

    @property
    def height(self) -> int:
        return max(18, min(34, self.size[1] // 16))

    @property
    def top(self) -> int:
        return self.size[1] - self.height - 6

    @property
    def left(self) -> float:
        return 40.0

    @property
    def right(self) -> float:
        return float(self.size[0]) - 40.0

    def x_of(self, frame: float) -> float:
        """Pixel column of ``frame``."""
        span = max(self.frames - 1, 1)
        return self.left + (self.right - self.left) * float(frame) / span

    def frame_at(self, x: float) -> int:
        """The frame under pixel column ``x`` (clamped to the clip)."""
        span = max(self.frames - 1, 1)
        f = round((float(x) - self.left) / max(self.right - self.left, 1.0) * span)
        return int(min(max(f, 0), self.frames - 1))

    def contains(self, x: float, y: float) -> bool:
        """Whether a press at ``(x, y)`` is on the strip."""
        return self.top - 4 <= y <= self.top + self.height + 4 and self.left - 12 <= x <= self.right + 12

    def key_at(self, x: float, keys: list[int]) -> int | None:
        """Index of the key whose diamond is under column ``x``, if any."""
        if not keys:
            return None
        d = np.abs(np.array([self.x_of(f) for f in keys]) - float(x))
        k = int(np.argmin(d))
        return k if d[k] <= PICK_KEY_PX else None

    def picture(self, keys: list[int], current: int) -> tuple[NDArray[np.uint8], tuple[float, float, float, float]]:
        """``(rgba, rect)``: the strip as an overlay image and its normalised place in the window."""
        w, h = self.size
        img = np.zeros((self.height, w, 4), dtype=np.uint8)
        x0, x1 = int(self.left) - 10, int(self.right) + 10
        img[:, x0:x1] = _STRIP_RGBA
        mid = self.height // 2
        step = max(1, self.frames // 120)
        for f in range(0, self.frames, step):
            x = int(round(self.x_of(f)))
            tall = 4 if f % 10 else 7
            img[mid - tall : mid + tall + 1, x] = (*_TICK_RGB, 255)
        cx = int(round(self.x_of(current)))
        img[2:-2, max(cx - 1, 0) : cx + 2] = (*CURSOR_RGB, 255)
        r = max(4, self.height // 4)
        yy, xx = np.mgrid[0 : self.height, -r : r + 1]
        diamond = np.abs(xx) + np.abs(yy - mid) <= r
        for f in sorted({f % self.frames for f in keys}):  # a loop's last key is its first
            x = int(round(self.x_of(f)))
            lo, hi = max(x - r, 0), min(x + r + 1, w)
            patch = img[:, lo:hi]
            patch[diamond[:, lo - (x - r) : hi - (x - r)]] = (*KEY_RGB, 255)
        return img, (0.0, self.top / h, 1.0, (self.top + self.height) / h)
