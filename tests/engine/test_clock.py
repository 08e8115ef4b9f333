"""The fixed-step clock: accumulator, bounded catch-up, pause, single step, alpha."""

import pytest

from engine.clock import FixedStepClock


def test_accumulates_partial_steps():
    c = FixedStepClock(dt=0.01)
    assert c.advance(0.005) == 0
    assert c.alpha == pytest.approx(0.5)
    assert c.advance(0.006) == 1
    assert c.alpha == pytest.approx(0.1, abs=1e-9)


def test_bounded_catch_up_drops_time():
    c = FixedStepClock(dt=0.25, max_steps=5)
    assert c.advance(10.0) == 5
    assert c.dropped_time == pytest.approx(35 * 0.25)
    assert c.accumulator == 0.0


def test_pause_and_single_step():
    c = FixedStepClock(dt=0.01)
    c.pause()
    assert c.advance(1.0) == 0
    c.request_step()
    assert c.advance(0.0) == 1
    assert c.advance(0.0) == 0
    c.resume()
    assert c.advance(0.025) == 2


def test_negative_time_refused():
    with pytest.raises(ValueError):
        FixedStepClock().advance(-1)
