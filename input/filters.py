"""The One Euro filter (Casiez, Roussel & Vogel, CHI 2012), vectorised and stateless.

Why One Euro: at low speeds jitter matters and a low cutoff removes it; at high
speeds lag matters and the cutoff rises with the speed. The state lives in the
caller's component (so it is hashed and replays bit-exactly) and the step is the
simulation's fixed ``dt``, never the wall clock.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["OneEuro", "smoothing_factor"]

from engine.arrays import F64 as F


def smoothing_factor(dt: float, cutoff: F | float) -> F | float:
    """Exponential smoothing factor of a first-order low-pass at ``cutoff`` Hz."""
    r = 2.0 * math.pi * cutoff * dt
    return r / (r + 1.0)


@dataclass(frozen=True)
class OneEuro:
    """Filter parameters: ``min_cutoff`` (Hz) at rest, ``beta`` speed coefficient, ``d_cutoff`` for the derivative."""

    min_cutoff: float = 1.5
    beta: float = 0.4
    d_cutoff: float = 4.0

    def step(self, x: F, raw_prev: F, x_prev: F, dx_prev: F, dt: float) -> tuple[F, F]:
        """Filter one new value ``x``; returns ``(x_hat, dx_hat)`` (value and its smoothed rate).

        ``raw_prev`` is the previous *input*; ``x_prev`` and ``dx_prev`` the previous outputs
        (``dx_prev`` zero at start). The rate is taken from the raw inputs, so it is the
        signal's speed and not the speed at which the smoothed value catches up.
        """
        dx = (x - raw_prev) / dt
        a_d = smoothing_factor(dt, self.d_cutoff)
        dx_hat = a_d * dx + (1.0 - a_d) * dx_prev
        cutoff = self.min_cutoff + self.beta * float(np.linalg.norm(dx_hat))
        a = smoothing_factor(dt, cutoff)
        x_hat = a * x + (1.0 - a) * x_prev
        return x_hat, dx_hat
