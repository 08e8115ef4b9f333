"""The snowman bench times a step in thread CPU time, as the median of fresh repeats.

Broken once: ``time.perf_counter`` back in ``_step_time`` makes the sleeping step cost its 10 ms
and the test fails; one repeat instead of ``REPEATS`` fails the count of apps built.
"""

from __future__ import annotations

import time

from puppetphone.bench.snowman import REPEATS, _step_time


class _SleepingApp:
    """A step that waits 10 ms without using the CPU: wall time sees it, thread CPU time does not."""

    def step(self) -> None:
        time.sleep(0.01)


def test_a_step_is_timed_in_thread_cpu_over_at_least_three_fresh_apps() -> None:
    built: list[_SleepingApp] = []

    def make() -> _SleepingApp:
        built.append(_SleepingApp())
        return built[-1]

    seconds, last = _step_time(make, steps=4)  # type: ignore[arg-type]  # a stand-in with App's step
    assert REPEATS >= 3
    assert len(built) == REPEATS, "each repeat steps a fresh app (the same deterministic stretch)"
    assert last is built[-1]
    assert seconds < 0.003, f"{seconds * 1e3:.1f} ms for a step that only sleeps: wall time, not CPU time"
