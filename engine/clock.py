"""The fixed-step clock: real time in, a whole number of simulation steps out.

The classic accumulator: real elapsed time is added, and each full ``dt`` in it
becomes one step. Catch-up is bounded (``max_steps`` per call, default 5) so a
long stall drops time instead of freezing in a spiral of death. ``alpha`` is the
fraction of a step left in the accumulator, which the renderer uses to
interpolate between the last two simulated states. Pause stops steps; while
paused, :meth:`request_step` lets exactly one through (single-step debugging).
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["FixedStepClock"]


@dataclass
class FixedStepClock:
    """Turns real elapsed seconds into fixed simulation steps."""

    dt: float = 1.0 / 60.0
    max_steps: int = 5
    paused: bool = False
    accumulator: float = 0.0
    dropped_time: float = 0.0
    _single_steps: int = 0

    SIM_STATE = False

    def advance(self, elapsed: float) -> int:
        """Add ``elapsed`` real seconds; return how many steps to run now."""
        if elapsed < 0:
            raise ValueError("elapsed time cannot be negative")
        if self.paused:
            steps, self._single_steps = self._single_steps, 0
            return steps
        self.accumulator += elapsed
        steps = int(self.accumulator // self.dt)
        self.accumulator -= steps * self.dt
        if steps > self.max_steps:
            self.dropped_time += (steps - self.max_steps) * self.dt
            steps = self.max_steps
        return steps

    @property
    def alpha(self) -> float:
        """Interpolation factor in [0,1) between the previous and the current state."""
        return 0.0 if self.paused else min(self.accumulator / self.dt, 1.0)

    def pause(self) -> None:
        """Stop stepping (the accumulator is kept for a smooth resume)."""
        self.paused = True

    def resume(self) -> None:
        """Start stepping again without a burst of catch-up steps."""
        self.paused = False
        self.accumulator = 0.0

    def request_step(self) -> None:
        """While paused, let one more step through on the next :meth:`advance`."""
        self._single_steps += 1
