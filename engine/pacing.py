"""Real-time pacing for headless runs driven by a live source.

A headless run with a phone must not race ahead of the phone, so the game loop
waits for each step's slot; with a replay source it runs as fast as it can (no
pacer). Sleeping is fine here: this sits outside the simulation, which only ever
sees the fixed ``dt``.

:class:`PhaseLock` moves the step schedule's phase (never its rate) so that steps
start just after a controller's readings arrive: a phone streaming at the step rate
otherwise keeps a fixed, arbitrary phase to the steps, and a reading that lands just
after a step waits almost a whole step, every time. Only wall-clock scheduling changes;
the simulation still sees the same frames in the same order.
"""

from __future__ import annotations

import time
from collections.abc import Callable

__all__ = ["RealTimePacer", "PhaseLock"]


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

    def shift(self, seconds: float) -> None:
        """Bring the next steps forward by ``seconds`` (negative: later): a phase change, not a rate change."""
        if self._next is not None:
            self._next -= seconds


class PhaseLock:
    """How far to move the step schedule so readings wait :attr:`target` seconds for their step.

    Each step, :meth:`error` takes the arrival times of the readings the step drained and
    the time it drained them; the newest reading's wait, minus the target wait, wrapped
    into half a step either way (a reading that just missed the previous step waited
    almost a whole one: the schedule is *late* by a little, not early by a lot), is the
    phase error. :meth:`correction` is a bounded fraction of it, to subtract from the
    schedule. The target is ``margin``, widened to three times the readings' jitter (the
    running mean of the error's size) when they arrive irregularly, as on a busy machine:
    a reading that misses its step waits a whole step more.

    Args:
        dt: the fixed step.
        margin: the smallest wait to aim at.
        gain: fraction of the error corrected per step.
        max_step: largest correction per step, in seconds.
    """

    def __init__(self, dt: float, margin: float = 0.004, gain: float = 0.2, max_step: float = 0.0005) -> None:
        self.dt, self.margin, self.gain, self.max_step = dt, margin, gain, max_step
        self.jitter = 0.0

    @property
    def target(self) -> float:
        """The wait aimed at: ``margin``, or more for jittery readings (at most 60 % of a step)."""
        return min(0.6 * self.dt, max(self.margin, 3.0 * self.jitter))

    def error(self, arrivals: list[float], drained_at: float) -> float | None:
        """The phase error in seconds (positive: steps come too late), or ``None`` without readings."""
        if not arrivals:
            return None
        waited = drained_at - max(arrivals)
        return (waited - self.target + self.dt / 2) % self.dt - self.dt / 2

    def correction(self, arrivals: list[float], drained_at: float) -> float:
        """Seconds to bring the schedule forward (negative: to hold it back); updates the jitter."""
        e = self.error(arrivals, drained_at)
        if e is None:
            return 0.0
        self.jitter += 0.05 * (abs(e) - self.jitter)
        return max(-self.max_step, min(self.max_step, self.gain * e))
