"""Real-time pacing for headless runs driven by a live source.

A headless run with a phone must not race ahead of the phone, so the game loop
waits for each step's slot; with a replay source it runs as fast as it can (no
pacer). Sleeping is fine here: this sits outside the simulation, which only ever
sees the fixed ``dt``.
"""

from __future__ import annotations

import time
from collections.abc import Callable

__all__ = ["RealTimePacer"]


class RealTimePacer:
    """Holds step ``n`` until ``start + n·dt`` of wall time.

    If the loop falls more than ``max_lag`` behind (a stall), the schedule is moved
    forward instead of running a burst of catch-up steps.

    Args:
        dt: the fixed step in seconds.
        clock, sleep: injectable for tests (default ``time.perf_counter``/``time.sleep``).
    """

    def __init__(self, dt: float, max_lag: float = 0.25, clock: Callable[[], float] = time.perf_counter,
                 sleep: Callable[[float], None] = time.sleep) -> None:
        if dt <= 0:
            raise ValueError("dt must be positive")
        self.dt, self.max_lag = dt, max_lag
        self._clock, self._sleep = clock, sleep
        self._next: float | None = None
        self.late_steps = 0

    def wait(self) -> None:
        """Block until the next step is due (the first call returns at once)."""
        now = self._clock()
        if self._next is None:
            self._next = now + self.dt
            return
        delay = self._next - now
        if delay > 0:
            self._sleep(delay)
        elif -delay > self.max_lag:
            self.late_steps += 1
            self._next = now
        self._next += self.dt
