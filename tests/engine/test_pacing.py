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


def test_phase_lock_brings_steps_to_just_after_the_readings():
    from engine.pacing import PhaseLock

    dt = 1 / 60
    c = FakeClock()
    pacer = RealTimePacer(dt, clock=c, sleep=c.sleep)
    lock = PhaseLock(dt, margin=0.005)
    phase = 0.0123  # readings arrive 12.3 ms into every step period: 4.4 ms before the next drain
    waits = []
    for n in range(200):
        pacer.wait()
        drained = c.t
        period = (drained - 100.0) // dt  # the newest reading is the one of the period just before
        arrival = 100.0 + period * dt + phase
        arrival -= dt if arrival > drained else 0.0
        waits.append(drained - arrival)
        pacer.shift(lock.correction([arrival], drained))
    assert abs(waits[3] - (dt - phase)) < 2e-3  # at first: the fixed, arbitrary phase
    assert all(abs(w - 0.005) < 1e-4 for w in waits[-50:])  # then: 5 ms after each reading
    assert lock.correction([], 0.0) == 0.0


def test_phase_lock_holds_back_after_a_reading_just_missed_its_step():
    from engine.pacing import PhaseLock

    lock = PhaseLock(1 / 60, margin=0.005, gain=1.0, max_step=1.0)
    assert lock.error([0.0], 0.016) == pytest.approx(-1 / 60 + 0.011)  # it just missed the step before: hold back
    assert lock.correction([0.0], 0.009) == pytest.approx(0.004)  # waited 9 ms: 4 ms earlier
