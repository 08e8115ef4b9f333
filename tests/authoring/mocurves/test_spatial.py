"""Spatial edits: Gaussian falloff of arrow edits (§5.1) and control-point drags."""

from __future__ import annotations

import numpy as np
import pytest

from authoring.mocurves.curves import mocurves
from authoring.mocurves.spatial import (
    control_basis,
    gaussian_weights,
    move_control_point,
    rotate_arrow,
    scale_arrow,
)
from engine import quat
from engine.fk import forward_kinematics


def test_gaussian_weights_follow_the_formula_and_wrap():
    w = gaussian_weights(20, 1, 3, 0.2)
    for j in range(20):
        d = min(abs(j - 1), 20 - abs(j - 1))
        assert w[j] == (pytest.approx(np.exp(-0.2 * d * d)) if d <= 3 else 0.0)
    assert w[18] > 0 and w[17] == 0.0  # 1 − 3 = −2 wraps to 18
    with pytest.raises(ValueError):
        gaussian_weights(20, 20, 3, 0.2)


def test_rotating_an_arrow_turns_neighbours_by_the_gaussian(walk):
    sk = walk.skeleton
    j = sk.index("l_lower_arm")
    i, tau, sigma = 10, 4, 0.15
    dtheta = np.array([0.0, 0.0, 0.6])
    edited = rotate_arrow(walk, j, i, dtheta, tau, sigma)
    _, before = forward_kinematics(sk, walk.root, walk.rotations)
    _, after = forward_kinematics(sk, edited.root, edited.rotations)
    turn = quat.mul(after[:, j], quat.conjugate(before[:, j]))
    angle = quat.angle_between(after[:, j], before[:, j])
    for f in range(walk.num_frames):
        expected = 0.6 * np.exp(-sigma * (f - i) ** 2) if abs(f - i) <= tau else 0.0
        assert angle[f] == pytest.approx(expected, abs=1e-7)  # arccos near 1 resolves ~1e-8
        if expected > 0:
            axis, _ = quat.to_axis_angle(turn[f])
            np.testing.assert_allclose(axis, [0.0, 0.0, 1.0], atol=1e-9)
    # The parent did not move; the children turned rigidly with the arm.
    np.testing.assert_allclose(after[:, sk.index("l_upper_arm")], before[:, sk.index("l_upper_arm")], atol=1e-12)
    child = sk.index("l_hand")
    np.testing.assert_allclose(quat.angle_between(after[:, child], before[:, child]), angle, atol=1e-7)


def test_scaling_an_arrow_propagates_in_log_scale(walk):
    s = np.ones((walk.num_frames, walk.skeleton.num_joints))
    out = scale_arrow(s, 3, 0, np.log(2.0), 2, 0.5)
    np.testing.assert_allclose(out[[0, 1, 2, 64, 65], 3], 2.0 ** np.exp(-0.5 * np.array([0, 1, 4, 4, 1])))
    assert np.all(out[3:64, 3] == 1.0) and np.all(out[:, [0, 1, 2, 4]] == 1.0)


def test_control_basis_is_a_partition_of_unity():
    b = control_basis(66, 13)
    np.testing.assert_allclose(b.sum(axis=1), 1.0)
    assert np.all(b >= 0)


def test_dragging_a_foot_control_point_moves_the_foot_by_the_basis(walk):
    sk = walk.skeleton
    j = sk.index("l_foot")
    curve = mocurves(walk)["l_foot"]
    k, delta = 13, np.array([0.0, 0.05, 0.02])
    edited = move_control_point(walk, j, curve.positions, k, 4, delta)
    moved = mocurves(edited)["l_foot"]
    expected = curve.positions + control_basis(walk.num_frames, k)[:, 4, None] * delta
    np.testing.assert_allclose(moved.positions, expected, atol=1e-6)
    np.testing.assert_allclose(quat.angle_between(moved.rotations, curve.rotations), 0.0, atol=1e-6)


def test_root_and_unpositionable_items(walk):
    sk = walk.skeleton
    root = mocurves(walk)["hips"]
    edited = move_control_point(walk, 0, root.positions, 13, 0, [0.1, 0.0, 0.0])
    assert edited.root[0, 0] == pytest.approx(walk.root[0, 0] + 0.1 * control_basis(66, 13)[0, 0])
    with pytest.raises(ValueError, match="follows its parents"):
        move_control_point(walk, sk.index("spine"), root.positions, 13, 0, [0.1, 0.0, 0.0])
