"""Eq. 6.3 and the three invalid jumps."""

import numpy as np
import pytest

from engine.statemachine.jump_arc import JumpStatus, JumpTracker, fit_parabola


def test_parabola_passes_both_points_with_the_slope():
    p = fit_parabola(0.3, 1.0, 1.1, 1.6, 0.4)
    assert p(0.3) == pytest.approx(1.0)
    assert p(1.1) == pytest.approx(1.6)
    assert 2 * p.a * 1.1 + p.b == pytest.approx(0.4)


def test_apex_of_a_true_parabola_is_exact_from_any_point():
    def true(x):
        return -2.0 * (x - 1.0) ** 2 + 1.5  # apex (1, 1.5), starts at (0, -0.5)

    def slope(x):
        return -4.0 * (x - 1.0)

    for xt in (0.2, 0.7, 1.4):
        p = fit_parabola(0.0, true(0.0), xt, true(xt), slope(xt))
        assert p.apex == pytest.approx((1.0, 1.5))


def simulate(path, dt=1 / 60):
    """Feed a sampled tip path (positions [T,3]) to a tracker; return the statuses."""
    vel = np.gradient(path, dt, axis=0)
    tracker = JumpTracker.start_at(path[0], vel[1])
    out = []
    for p, v in zip(path[1:], vel[1:]):
        s = tracker.update(p, v, dt, p[1])
        out.append(s)
        if s not in (JumpStatus.RISING, JumpStatus.FALLING):
            break
    return out, tracker


def ballistic(t, v0=(0.0, 3.5, 2.0), g=9.81):
    t = np.asarray(t)[:, None]
    p = np.array([0.0, 0.0, 0.0]) + np.array(v0) * t
    p[:, 1] -= 0.5 * g * t[:, 0] ** 2
    return p


def test_valid_jump_rises_falls_lands_with_apex():
    t = np.arange(0, 0.75, 1 / 60)
    statuses, tracker = simulate(ballistic(t))
    assert statuses[-1] == JumpStatus.LANDED
    assert JumpStatus.RISING in statuses and JumpStatus.FALLING in statuses
    apex_x = 2.0 * 3.5 / 9.81
    assert tracker.apex[0] == pytest.approx(apex_x, abs=0.05)
    assert tracker.apex[1] == pytest.approx(3.5**2 / (2 * 9.81), abs=0.05)


def test_rising_again_is_invalid():
    t = np.arange(0, 0.7, 1 / 60)
    p = ballistic(t)
    p[30:, 1] += np.linspace(0, 1.5, len(p) - 30)  # lifted again while falling
    statuses, _ = simulate(p)
    assert statuses[-1] == JumpStatus.ROSE_AGAIN


def test_turning_in_the_air_is_invalid():
    t = np.arange(0, 0.7, 1 / 60)
    p = ballistic(t)
    p[15:, 0] += np.cumsum(np.full(len(p) - 15, 0.08))  # swerves sideways
    statuses, _ = simulate(p)
    assert statuses[-1] == JumpStatus.TURNED


def test_stopping_in_the_air_is_invalid():
    t = np.arange(0, 0.3, 1 / 60)
    p = ballistic(t, v0=(0, 3.0, 1.5))
    hold = np.repeat(p[-1:], 30, axis=0)
    statuses, _ = simulate(np.vstack([p, hold]))
    assert statuses[-1] == JumpStatus.STOPPED
