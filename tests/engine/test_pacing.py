import numpy as np
import pytest

from engine.pacing import RealTimePacer


class FakeClock:
    def __init__(self):
        self.t = 100.0
        self.slept = []

    def __call__(self):
        return self.t

    def sleep(self, s):
        self.slept.append(round(s, 9))
        self.t += s


def test_paces_to_real_time_and_skips_ahead_after_a_stall():
    c = FakeClock()
    p = RealTimePacer(0.01, max_lag=0.05, clock=c, sleep=c.sleep)
    p.wait()
    c.t += 0.004  # the step took 4 ms
    p.wait()
    assert c.slept == [0.006]
    c.t += 0.5  # a stall
    p.wait()
    assert p.late_steps == 1 and len(c.slept) == 1
    p.wait()  # the schedule moved on: the next step waits a whole step, no burst
    assert c.slept[-1] == 0.01


def test_rejects_bad_dt():
    with pytest.raises(ValueError):
        RealTimePacer(0.0)


class FakeEvent:
    """A wake event on the fake clock: ``arrivals`` are the times readings are queued."""

    def __init__(self, clock, arrivals=()):
        self.clock, self.arrivals, self.flag = clock, sorted(arrivals), False
        self.waits = []

    def _catch_up(self):
        while self.arrivals and self.arrivals[0] <= self.clock.t:
            self.arrivals.pop(0)
            self.flag = True

    def wait(self, timeout):
        self.waits.append(round(timeout, 9))
        self._catch_up()
        if self.flag:
            return True
        if self.arrivals and self.arrivals[0] <= self.clock.t + timeout:
            self.clock.t = self.arrivals.pop(0)
            self.flag = True
            return True
        self.clock.t += timeout
        return False

    def clear(self):
        self._catch_up()  # a reading queued before this moment was drained by the step about to run
        self.flag = False


def test_a_reading_starts_its_step_early_but_only_within_the_window():
    c = FakeClock()
    dt = 0.01
    ev = FakeEvent(c, arrivals=[100.012, 100.0285])
    p = RealTimePacer(dt, clock=c, sleep=c.sleep, wake=ev, early=0.004)
    p.wait()  # step 0 at 100.0; slot 1 at 100.01 with no reading: waits for the slot
    p.wait()
    assert c.t == pytest.approx(100.01) and p.early_steps == 0
    p.wait()  # a reading at 100.012 was queued long before the window opened at 100.016: step at once then
    assert c.t == pytest.approx(100.016) and p.early_steps == 1
    p.wait()  # the window for slot 3 opens at 100.026, the reading comes at 100.0285: step then
    assert c.t == pytest.approx(100.0285) and p.early_steps == 2
    p.wait()  # that reading was used: the next step waits for its slot
    assert c.t == pytest.approx(100.04) and p.early_steps == 2


def test_early_steps_keep_the_rate_and_never_burst():
    dt = 1 / 60
    c = FakeClock()
    rng = np.random.default_rng(1)
    arrivals = 100.0 + np.cumsum(rng.uniform(0.2 * dt, 1.8 * dt, 3000))  # readings at a jittery ~60 Hz
    ev = FakeEvent(c, arrivals.tolist())
    p = RealTimePacer(dt, clock=c, sleep=c.sleep, wake=ev)
    starts = []
    for _ in range(1000):
        p.wait()
        starts.append(c.t)
        c.t += 0.001  # the step's work
    gaps = np.diff(starts)
    assert p.early_steps > 300
    assert gaps.min() >= dt / 2 - 1e-9  # at most half a step early: never two steps back to back
    assert (starts[-1] - starts[0]) / 999 == pytest.approx(dt, abs=dt / 999)  # the average rate is the step rate
    slots = 100.0 + dt * np.arange(1000)
    assert np.all(np.array(starts) <= slots + 1e-9) and np.all(np.array(starts) >= slots - dt / 2 - 1e-9)


def test_rejects_an_early_window_of_a_whole_step():
    with pytest.raises(ValueError):
        RealTimePacer(0.01, early=0.01)


def test_the_time_keeper_judges_the_last_seconds_after_the_first_one() -> None:
    from engine.pacing import TimeKeeper

    keeper = TimeKeeper(0.25, span=2.0)
    keeper.frame(1.5, 1.25)  # the first frame: shaders compiling, not judged
    for _ in range(5):
        keeper.frame(0.1, 0.0)
    assert keeper.behind() is None and keeper.kept() == 1.0
    for _ in range(5):
        keeper.frame(0.5, 0.25)  # stalls: half of each frame dropped
    assert keeper.kept() < 0.6 and "too slow to keep time" in (keeper.behind() or "")
    for _ in range(25):
        keeper.frame(0.1, 0.0)  # two seconds on time: the stalls have left the window
    assert keeper.behind() is None
