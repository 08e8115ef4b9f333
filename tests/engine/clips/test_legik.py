"""The authoring leg IK reaches its targets exactly, bends knees forward and sets the foot."""

from __future__ import annotations

import numpy as np

from engine import quat
from engine.clips._legik import solve_leg

THIGH, SHIN = 0.42, 0.42


def _chain(hip: np.ndarray, parent: np.ndarray, sol) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    up_w = quat.mul(parent, sol.upper)
    knee = hip + quat.rotate(up_w, [0.0, -THIGH, 0.0])
    shin_w = quat.mul(up_w, sol.knee)
    ankle = knee + quat.rotate(shin_w, [0.0, -SHIN, 0.0])
    return knee, ankle, quat.mul(shin_w, sol.foot)


def test_reachable_targets_are_hit_with_the_requested_foot_rotation() -> None:
    rng = np.random.default_rng(3)
    n = 200
    hip = rng.normal(size=(n, 3))
    parent = quat.normalize(rng.normal(size=(n, 4)))
    direction = rng.normal(size=(n, 3))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    dist = rng.uniform(0.1, 0.83, size=(n, 1))
    ankle = hip + direction * dist
    pole = rng.normal(size=(n, 3))
    foot = quat.normalize(rng.normal(size=(n, 4)))
    sol = solve_leg(hip, parent, ankle, pole, foot, THIGH, SHIN)
    knee, reached, foot_w = _chain(hip, parent, sol)
    np.testing.assert_allclose(reached, ankle, atol=1e-9)
    assert np.all(quat.angle_between(foot_w, foot) < 1e-6)
    assert np.all(sol.knee_flex >= 0.0)
    # The knee bends towards the pole: it lies on the pole's side of the hip-ankle line.
    u = direction
    off = knee - hip - np.sum((knee - hip) * u, axis=1, keepdims=True) * u
    pole_perp = pole - np.sum(pole * u, axis=1, keepdims=True) * u
    assert np.all(np.sum(off * pole_perp, axis=1) > 0.0)


def test_knee_is_a_forward_hinge_about_local_x() -> None:
    hip = np.array([[0.09, 0.9, 0.0]])
    ankle = np.array([[0.09, 0.3, 0.1]])
    sol = solve_leg(hip, quat.identity(1), ankle, np.array([[0.0, 0.0, 1.0]]), quat.identity(1), THIGH, SHIN)
    axis, angle = quat.to_axis_angle(sol.knee)
    np.testing.assert_allclose(axis[0], [1.0, 0.0, 0.0], atol=1e-9)
    assert 0.5 < angle[0] < 2.5
    knee, _, _ = _chain(hip, quat.identity(1), sol)
    assert knee[0, 2] > hip[0, 2] + 0.05  # the knee comes forward (+Z), not backward


def test_unreachable_target_stretches_towards_it_and_reports_reach() -> None:
    hip = np.zeros((1, 3))
    ankle = np.array([[0.0, -2.0, 0.0]])
    sol = solve_leg(hip, quat.identity(1), ankle, np.array([[0.0, 0.0, 1.0]]), quat.identity(1), THIGH, SHIN)
    assert sol.reach[0] > 2.0
    _, reached, _ = _chain(hip, quat.identity(1), sol)
    assert np.linalg.norm(reached[0]) < THIGH + SHIN
    assert reached[0, 1] < -0.8
