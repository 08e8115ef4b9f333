"""Real-time pacing: for headless runs driven by a live source, and the window's account of lost time.

A headless run with a phone must not race ahead of the phone, so the game loop
waits for each step's slot; with a replay source it runs as fast as it can (no
pacer). Sleeping is fine here: this sits outside the simulation, which only ever
sees the fixed ``dt``.

:class:`RealTimePacer` can also be woken by a reading (``wake``, an event the input hub
sets): within ``early`` seconds before a slot, a reading starts the step at once
instead of waiting for the slot. A phone streaming at the step rate otherwise keeps an
arbitrary phase to the steps, and a reading that lands just after a step waits almost a
whole one; locking the schedule's phase to the readings (tried before) cannot beat the
jitter of the phone's own sensor tick, waking on arrival does not need to. The schedule
still advances by exactly ``dt`` per step, so the rate is unchanged and early steps never
add up to a burst. Only wall-clock scheduling changes; the simulation still sees the
same frames in the same order.
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Callable

__all__ = ["RealTimePacer", "TimeKeeper"]


class RealTimePacer:
    """Holds step ``n`` until ``start + n·dt`` of wall time.

    If the loop falls more than ``max_lag`` behind (a stall), the schedule is moved
    forward instead of running a burst of catch-up steps.

    With ``wake``, step ``n`` may start as early as ``start + n·dt - early`` when the
    event is set (a reading arrived); the event is cleared as the step is released, so
    each reading wakes at most one step. Steps are then at least ``dt - early`` apart.

    Args:
        dt: the fixed step in seconds.
        clock, sleep: injectable for tests (default ``time.perf_counter``/``time.sleep``).
        wake: set when a reading arrives (:attr:`input.hub.InputHub.arrived`); ``None``: slots only.
        early: how long before its slot a reading may start a step; default half a step.
    """

    def __init__(
        self,
        dt: float,
        max_lag: float = 0.25,
        clock: Callable[[], float] = time.perf_counter,
        sleep: Callable[[float], None] = time.sleep,
        wake: threading.Event | None = None,
        early: float | None = None,
    ) -> None:
        if dt <= 0:
            raise ValueError("dt must be positive")
        self.dt, self.max_lag = dt, max_lag
        self.early = dt / 2 if early is None else early
        if not 0 <= self.early < dt:
            raise ValueError("early must be in [0, dt)")
        self._clock, self._sleep, self._wake = clock, sleep, wake
        self._next: float | None = None
        self.late_steps = 0
        self.early_steps = 0

    def wait(self) -> None:
        """Block until the next step is due (the first call returns at once)."""
        now = self._clock()
        if self._next is None:
            self._next = now + self.dt
            self._release()
            return
        delay = self._next - now
        if delay > 0 and self._wake is not None:
            if delay > self.early:
                self._sleep(delay - self.early)
                delay = self._next - self._clock()
            if delay > 0 and self._wake.wait(delay):
                self.early_steps += 1
        elif delay > 0:
            self._sleep(delay)
        elif -delay > self.max_lag:
            self.late_steps += 1
            self._next = now
        self._next += self.dt
        self._release()

    def _release(self) -> None:
        """Readings from here on belong to the next step: only they may wake it."""
        if self._wake is not None:
            self._wake.clear()


class TimeKeeper:
    """How far a window's game time falls behind wall time, over the last few seconds.

    The runner tells it each frame's wall duration and how much of it was dropped (a
    stall longer than the catch-up limit, or steps beyond the clock's cap). Once ``span``
    seconds are judged, while the game kept less than ``keep`` of the wall time of the last ``span`` seconds,
    :meth:`behind` says so in words for the screen, and the first time it happens in a
    run a line goes to stderr; otherwise the window says nothing.

    The first ``grace`` seconds of a run are not judged: the first frames compile shaders
    and fill caches, and a stall there says nothing about the game. Nor are the frames before a
    change of the drawing level (:meth:`restart`).

    Args:
        max_frame: the runner's catch-up limit, named in the message.
        span: seconds of history judged.
        keep: the share of wall time the game must keep to count as on time.
        grace: seconds at the start not judged.
    """

    def __init__(self, max_frame: float, span: float = 2.0, keep: float = 0.98, grace: float = 1.0) -> None:
        self.max_frame, self.span, self.keep = max_frame, span, keep
        self.grace = grace
        self._grace = grace
        self._frames: list[tuple[float, float]] = []
        self.dropped_total = 0.0
        self._warned = False

    def frame(self, elapsed: float, dropped: float) -> None:
        """One frame of ``elapsed`` wall seconds, ``dropped`` of which the game did not run."""
        if self._grace > 0:
            self._grace -= elapsed
            return
        self._frames.append((elapsed, dropped))
        self.dropped_total += dropped
        total = 0.0
        for i in range(len(self._frames) - 1, -1, -1):
            total += self._frames[i][0]
            if total >= self.span:
                del self._frames[:i]
                break

    def restart(self) -> None:
        """Judge afresh, after ``grace`` seconds again: the drawing level changed, and the frames drawn at the
        level left (1000 puppets at ``medium`` on a laptop: 3 fps, the reason it was left) say nothing about
        the new one, whose first frames compile its shaders. The terminal line is still said only once."""
        self._frames.clear()
        self._grace = self.grace

    def kept(self) -> float:
        """Share of the recent wall time the game kept (1 when nothing was dropped)."""
        wall = sum(e for e, _ in self._frames)
        return 1.0 if wall <= 0 else 1.0 - sum(d for _, d in self._frames) / wall

    def behind(self) -> str | None:
        """What to tell the player while the game runs slower than real time, else ``None``."""
        wall = sum(e for e, _ in self._frames)
        if wall < self.span:  # not yet a whole span judged (a run's start, or a level just changed)
            return None
        kept = self.kept()
        if kept >= self.keep:
            return None
        fps = len(self._frames) / wall if wall > 0 else 0.0
        text = (
            f"too slow to keep time: the game runs at {kept:.2f}x real time ({fps:.1f} fps, "
            f"frames over {self.max_frame * 1000:.0f} ms); G lowers the quality"
        )
        if not self._warned:
            self._warned = True
            print(f"puppetphone: {text}", file=sys.stderr)
        return text
