"""The locomotion control (``follow.py``) asserted on what it promises, one step at a time.

The spring is exact for any step and never overshoots; the wanted velocity is the stick's own
(once it leads) plus a catch-up faded in over the dead band and capped at the top speed; the puppet
turns toward its velocity at a bounded rate that is quicker when slow and zero at rest, and walks
only as fast as its facing allows; braking is twice as stiff; only the ground plane counts.
Before these tests only the recorded sessions' golden hashes watched this module.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from engine import quat
from engine.components import Transform
from engine.ecs import World
from engine.statemachine.puppet.body import PuppetBody, PuppetTuning
from engine.statemachine.puppet.follow import drag_reach, follow_velocity, spring_step, wanted_velocity

T = PuppetTuning()
DT = 1.0 / 60.0


class _Player:
    """Stands in for the LocomotionPlayer: the control only writes its requested ``speed``."""

    speed = -1.0


def _v(x: float, z: float, y: float = 0.0) -> np.ndarray:
    return np.array([x, y, z])


# --- the spring --------------------------------------------------------------------------------


def _closed_form(x0: float, v0: float, omega: float, t: float) -> tuple[float, float]:
    """A critically damped spring at time ``t``: ``x = (x0 + (v0 + ωx0) t) e^{-ωt}`` and its derivative."""
    e = np.exp(-omega * t)
    return (x0 + (v0 + omega * x0) * t) * e, (v0 - omega * (v0 + omega * x0) * t) * e


@pytest.mark.parametrize(("dt", "steps"), [(0.2, 1), (0.01, 20), (0.001, 200)])
def test_the_spring_lands_on_the_exact_solution_whatever_the_step(dt: float, steps: int) -> None:
    value, rate, goal = _v(1.5, -2.0), _v(0.3, 4.0), _v(0.5, 1.0)
    for _ in range(steps):
        value, rate = spring_step(value, rate, goal, 12.0, dt)
    for axis in (0, 2):
        x, v = _closed_form(float((_v(1.5, -2.0) - goal)[axis]), float(_v(0.3, 4.0)[axis]), 12.0, dt * steps)
        assert value[axis] == pytest.approx(goal[axis] + x, abs=1e-12)
        assert rate[axis] == pytest.approx(v, abs=1e-12)


def test_the_spring_takes_a_step_change_without_overshoot_ninety_percent_in_3_89_over_omega() -> None:
    value, rate, goal = _v(0.0, 0.0), _v(0.0, 0.0), _v(0.0, 2.0)
    path = []
    for _ in range(120):
        value, rate = spring_step(value, rate, goal, 20.0, DT)
        path.append(float(value[2]))
    assert np.all(np.diff(path) > 0.0) and max(path) < 2.0
    t90 = 3.89 / 20.0
    assert path[round(t90 / DT) - 1] == pytest.approx(1.8, abs=0.02)


# --- the wanted velocity -------------------------------------------------------------------------


def test_a_puppet_at_a_still_stick_is_asked_for_nothing() -> None:
    assert np.array_equal(wanted_velocity(_v(0.0, 0.0), _v(0.0, 0.0), T), np.zeros(3))


def test_with_no_dead_band_a_puppet_at_its_stick_still_gets_a_number() -> None:
    """A tuning without a dead band: zero distance is no catch-up (not 0/0)."""
    assert np.array_equal(wanted_velocity(_v(0.0, 0.0), _v(0.0, 0.0), replace(T, follow_deadband=0.0)), np.zeros(3))


def test_the_catch_up_fades_in_over_the_dead_band() -> None:
    """Half the gain at the dead band's distance, nearly none for a tremor, nearly all far out."""
    band = T.follow_deadband
    at_band = wanted_velocity(_v(band, 0.0), _v(0.0, 0.0), T)
    assert at_band == pytest.approx(_v(0.5 * T.catch_up_gain * band, 0.0))
    tremor = wanted_velocity(_v(0.0, band / 6.0), _v(0.0, 0.0), T)
    assert tremor[2] == pytest.approx(T.catch_up_gain * band / 6.0 / 37.0)
    far = wanted_velocity(_v(0.0, -1.0), _v(0.0, 0.0), T)
    assert far == pytest.approx(_v(0.0, -T.catch_up_gain / (1.0 + band**2)))


@pytest.mark.parametrize(("ahead", "share"), [(0.05, 1.0), (0.02, 1.0), (0.01, 0.5), (0.0, 0.0), (-0.03, 0.0)])
def test_the_sticks_velocity_counts_once_the_stick_leads(ahead: float, share: float) -> None:
    """The stick moves at 1.2 m/s along +X: its velocity counts in full once it leads by 2 cm, by half at
    1 cm, not at all level with the puppet or behind it."""
    lead = _v(1.2, 0.0)
    error = _v(ahead, 0.0)
    catch_up = wanted_velocity(error, _v(0.0, 0.0), T)
    assert wanted_velocity(error, lead, T) == pytest.approx(share * lead + catch_up)


def test_a_crouched_puppet_asks_for_a_longer_lead() -> None:
    lead = _v(0.0, 1.0)
    catch_up = wanted_velocity(_v(0.0, 0.03), _v(0.0, 0.0), T)
    assert wanted_velocity(_v(0.0, 0.03), lead, T, lead_band=0.06) == pytest.approx(0.5 * lead + catch_up)


def test_a_stick_moving_across_the_puppet_is_not_a_lead() -> None:
    """The stick 5 cm to the side, moving forward: it does not lead along its motion."""
    lead = _v(0.0, 1.0)
    assert wanted_velocity(_v(0.05, 0.0), lead, T) == pytest.approx(wanted_velocity(_v(0.05, 0.0), _v(0.0, 0.0), T))


def test_the_request_is_capped_at_the_top_speed_in_its_direction() -> None:
    out = wanted_velocity(_v(30.0, 40.0), _v(3.0, 4.0), T)
    assert out == pytest.approx(_v(0.6, 0.8) * T.top_speed)
    just_under = wanted_velocity(_v(0.0, 1.0), _v(0.0, T.top_speed - T.catch_up_gain), T)
    assert np.linalg.norm(just_under) < T.top_speed


def test_the_drag_reach_grows_with_the_puppets_speed_not_the_sticks() -> None:
    body = PuppetBody(walk_velocity=_v(3.0, 4.0), lead=_v(50.0, 0.0))
    assert drag_reach(body) == pytest.approx(T.drag_limit + 5.0 * T.drag_lead_time)
    assert drag_reach(PuppetBody(lead=_v(50.0, 0.0))) == T.drag_limit


# --- one step of the control ---------------------------------------------------------------------


_AT = np.array([1.0, 0.9, 2.0])  # where the puppet stands (its hips): not the origin


def _puppet(
    heading: float = 0.0,
    walk: np.ndarray | None = None,
    ahead: np.ndarray | None = None,
    lead: np.ndarray | None = None,
    held: bool = True,
) -> tuple[World, int, PuppetBody, _Player]:
    """A puppet at ``_AT`` whose stick is ``ahead`` of it (world offset), moving at ``lead``."""
    world = World(dt=DT)
    body = PuppetBody(
        held_by=7 if held else None,
        heading=heading,
        target=_AT + (np.zeros(3) if ahead is None else ahead),
        lead=np.zeros(3) if lead is None else lead,
        walk_velocity=np.zeros(3) if walk is None else walk,
    )
    entity = world.spawn(Transform(position=np.array(_AT)), body)
    return world, entity, body, _Player()


def test_the_velocity_follows_the_spring_toward_the_wanted_velocity() -> None:
    """The stick 0.03 m ahead and up, moving forward and up: only its ground offset and motion count."""
    world, e, body, player = _puppet(ahead=_v(0.018, 0.024, 0.5), lead=_v(0.6, 0.8, 2.0))
    goal = wanted_velocity(_v(0.018, 0.024), _v(0.6, 0.8), T)
    v, r = spring_step(_v(0.0, 0.0), _v(0.0, 0.0), goal, T.follow_omega, DT)
    follow_velocity(world, e, body, player)
    assert body.walk_velocity == pytest.approx(v) and body.walk_rate == pytest.approx(r)
    assert body.heading == pytest.approx(_turn_rate(float(np.linalg.norm(v))) * DT)
    assert player.speed == pytest.approx(float(np.linalg.norm(v)) * np.cos(np.arctan2(0.6, 0.8) - body.heading))
    assert np.array_equal(body.recent[-1], body.walk_velocity) and not body.recent[:-1].any()


def test_only_the_ground_plane_counts() -> None:
    """The stick straight above the puppet, moving up: nothing to walk toward."""
    world, e, body, player = _puppet(ahead=_v(0.0, 0.0, 3.0), lead=_v(0.0, 0.0, 2.0))
    follow_velocity(world, e, body, player)
    assert not body.walk_velocity.any() and player.speed == 0.0


def test_braking_is_twice_as_stiff_and_a_released_puppet_stops() -> None:
    world, e, body, player = _puppet(walk=_v(0.0, 2.0), held=False, ahead=_v(0.0, 5.0))
    v, _ = spring_step(_v(0.0, 2.0), _v(0.0, 0.0), np.zeros(3), 2.0 * T.follow_omega, DT)
    follow_velocity(world, e, body, player)
    assert body.walk_velocity == pytest.approx(v)
    for _ in range(60):
        follow_velocity(world, e, body, player)
    assert np.linalg.norm(body.walk_velocity) < 1e-6
    speed = float(np.linalg.norm(body.walk_velocity))
    assert 0.0 < speed < 1e-3 and player.speed == pytest.approx(speed, rel=1e-9, abs=0.0)  # still facing it


def test_turning_at_the_same_speed_is_not_braking() -> None:
    """Asked for the same speed in a new direction, the spring keeps its normal stiffness."""
    goal = wanted_velocity(_v(0.05, 0.0), _v(1.0, 0.0), T)
    walk = _v(goal[2], -goal[0])  # the same speed, at a right angle
    world, e, body, player = _puppet(walk=walk, ahead=_v(0.05, 0.0), lead=_v(1.0, 0.0))
    v, _ = spring_step(walk, np.zeros(3), goal, T.follow_omega, DT)
    follow_velocity(world, e, body, player)
    assert body.walk_velocity == pytest.approx(v)


def test_the_lead_band_is_passed_on() -> None:
    """Crouched (a 6 cm lead band), a stick 3 cm ahead gives half its velocity."""
    world, e, body, player = _puppet(ahead=_v(0.0, 0.03), lead=_v(0.0, 1.0))
    v, _ = spring_step(
        np.zeros(3), np.zeros(3), wanted_velocity(_v(0.0, 0.03), _v(0.0, 1.0), T, 0.06), T.follow_omega, DT
    )
    follow_velocity(world, e, body, player, lead_band=0.06)
    assert body.walk_velocity == pytest.approx(v)


def test_the_history_keeps_the_last_twelve_requests_oldest_first() -> None:
    world, e, body, player = _puppet(ahead=_v(1.0, 1.0), lead=_v(1.0, 1.0))
    seen = []
    for _ in range(14):
        follow_velocity(world, e, body, player)
        seen.append(np.array(body.walk_velocity))
    assert np.array_equal(body.recent, np.array(seen[-12:]))


def _turn_rate(speed: float) -> float:
    return T.turn_rate * (1.0 + 1.0 / (1.0 + speed)) * float(np.clip((speed - 0.1) / 0.1, 0.0, 1.0))


@pytest.mark.parametrize("speed", [0.05, 0.25, 0.5, 3.0])
def test_the_turn_is_bounded_quicker_when_slow_and_nothing_at_rest(speed: float) -> None:
    """Led at a right angle (+X) while facing +Z, the puppet turns by at most its rate this step: the
    full rate above 0.2 m/s (twice as quick standing as running fast), ramped in from 0.1 m/s."""
    v0 = _v(speed, 0.0)
    world, e, body, player = _puppet(walk=v0)  # at the stick: it slows (braking)
    v, _ = spring_step(v0, np.zeros(3), np.zeros(3), 2.0 * T.follow_omega, DT)
    follow_velocity(world, e, body, player)
    s = float(np.linalg.norm(v))
    assert body.heading == pytest.approx(_turn_rate(s) * DT, abs=1e-12)
    assert np.allclose(world.get(e, Transform).rotation, quat.from_axis_angle(np.array([0.0, 1.0, 0.0]), body.heading))
    facing = max(float(np.sin(body.heading)), 0.0)
    assert player.speed == pytest.approx(s * facing)


def test_a_puppet_facing_away_does_not_walk_backwards_and_the_speed_scale_scales() -> None:
    world, e, body, player = _puppet(heading=np.pi, walk=_v(0.0, 2.0), ahead=_v(0.0, 2.0), lead=_v(0.0, 2.0))
    follow_velocity(world, e, body, player)
    assert player.speed == 0.0
    world, e, body, player = _puppet(walk=_v(0.0, 2.0), ahead=_v(0.0, 2.0), lead=_v(0.0, 2.0))
    follow_velocity(world, e, body, player, speed_scale=0.5)
    assert player.speed == pytest.approx(0.5 * float(np.linalg.norm(body.walk_velocity)))


def test_the_turn_takes_the_short_way_across_the_back() -> None:
    """Facing 175°, led toward -175°: it turns 10° through 180°, not 350° the long way, and its heading
    stays in [-π, π)."""
    d = np.radians(-175.0)
    world, e, body, player = _puppet(
        heading=np.radians(175.0), walk=2.0 * _v(np.sin(d), np.cos(d)), ahead=5.0 * _v(np.sin(d), np.cos(d))
    )
    before = body.heading
    for _ in range(3):
        follow_velocity(world, e, body, player)
    moved = (body.heading - before + np.pi) % (2 * np.pi) - np.pi
    assert moved > 0.0 and -np.pi <= body.heading < np.pi
    assert body.heading < 0.0  # crossed the back
