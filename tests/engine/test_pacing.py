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
