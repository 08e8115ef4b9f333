"""The optimisation IK (thesis Eq. 4.13): reaches, holds pins within ε, respects limits, rejects the impossible."""

from __future__ import annotations

import numpy as np
import pytest

from engine import quat
from engine.fk import forward_kinematics
from engine.humanoid import humanoid_skeleton
from engine.ik import Effector, IKRig, IKSettings, Pin, humanoid_rig, solve_ik
from puppetphone.bench.ik import TIP, chain_skeleton, chain_targets, pin_joints


def _world(sk, root, rot):
    return forward_kinematics(sk, root, rot)


@pytest.mark.parametrize("pins", [0, 1, 3])
def test_reaches_reachable_targets_and_keeps_pins(pins):
    joints = 10
    sk = chain_skeleton(joints)
    rig = IKRig.build(sk, limits=dict.fromkeys(sk.names, (-1.5, 1.5)))
    pj = pin_joints(joints, pins)
    eps = IKSettings().pin_epsilon
    for c0, target in chain_targets(rig, pj, 6, seed=pins):
        root, rot = rig.to_pose(c0, quat.identity(joints), np.zeros(3))
        wp0, _ = _world(sk, root, rot)
        res = solve_ik(rig, root, rot, [Effector(joints - 1, target, point=TIP)], [Pin(j) for j in pj])
        assert res.reached
        wp, wr = _world(sk, res.root, res.rotations)
        assert np.linalg.norm(wp[-1] + quat.rotate(wr[-1], TIP) - target) < 1e-3
        for j in pj:
            assert np.max(np.abs(wp[j] - wp0[j])) <= eps * (1 + 1e-6)
        assert rig.within_limits(res.coordinates)


def test_limits_hold_when_the_target_pulls_against_them():
    sk = humanoid_skeleton()
    rig = humanoid_rig(sk)
    pose_root, rot = np.array([0.0, 0.95, 0.0]), quat.identity(17)
    # a hand target behind the back and high: elbows and shoulders hit their limits on the way
    res = solve_ik(rig, pose_root, rot, [Effector("l_hand", [0.3, 1.5, -0.35])], [Pin("hips")])
    assert rig.within_limits(res.coordinates)
    c, _ = rig.to_coordinates(res.closest_root, res.closest_rotations)
    assert rig.within_limits(c, tol=1e-6)
    knee = sk.index("l_lower_arm")
    assert res.coordinates[rig.dof_joint == knee][0] >= 0.0


def test_unreachable_target_is_reported_and_pose_kept():
    """A bent chain asked to reach a point beyond its length, off to one side: the pose is kept, and the
    closest pose (the chain stretched towards the target) is reported apart.

    Repaired: the chain used to start straight with the target along it, so the input pose, the
    closest pose and "pose kept" were all the same thing. Shown to fail when the solver returns the
    closest pose as the result (``out_root, out_rot = best_root, best_rot`` whatever ``done``), or
    reports the input as the closest pose.
    """
    joints = 6
    sk = chain_skeleton(joints)
    rig = IKRig.build(sk)
    rot = quat.exp(np.tile([0.25, 0.0, 0.15], (joints, 1)))
    root = np.zeros(3)
    target = np.array([1.5, 0.8, -1.0])  # 1.97 m away; the chain with its tip is 0.6 m long
    res = solve_ik(rig, root, rot, [Effector(joints - 1, target, point=TIP)])
    assert not res.reached
    assert np.array_equal(res.rotations, rot) and np.array_equal(res.root, root)
    assert res.iterations < IKSettings().max_iterations  # rejected after non-improving iterations
    # the closest pose points the chain at the target, fully stretched, and is far from the input
    wp, wr = _world(sk, res.closest_root, res.closest_rotations)
    tip = wp[-1] + quat.rotate(wr[-1], TIP)
    assert np.linalg.norm(tip) == pytest.approx(0.6, abs=5e-3)
    assert tip @ target / (np.linalg.norm(tip) * np.linalg.norm(target)) > 0.99
    wp0, wr0 = _world(sk, root, rot)
    assert np.linalg.norm(tip - (wp0[-1] + quat.rotate(wr0[-1], TIP))) > 0.5
    assert res.error == pytest.approx(np.linalg.norm(target - tip), abs=1e-6)


def test_pins_make_a_target_unreachable():
    joints = 6
    sk = chain_skeleton(joints)
    rig = IKRig.build(sk)
    rot = quat.exp(np.tile([0.2, 0.0, 0.1], (joints, 1)))
    wp, _ = _world(sk, np.zeros(3), rot)
    # the pinned joint 4 is 0.2 m from the tip at most: a target 0.5 m from it cannot be reached
    target = wp[4] + np.array([0.5, 0.0, 0.0])
    res = solve_ik(rig, np.zeros(3), rot, [Effector(joints - 1, target, point=TIP)], [Pin(4)])
    assert not res.reached
    wp2, _ = _world(sk, res.closest_root, res.closest_rotations)
    assert np.max(np.abs(wp2[4] - wp[4])) < 2e-4


def test_any_joint_is_an_effector_with_orientation():
    sk = humanoid_skeleton()
    rig = humanoid_rig(sk, root_translation=True)
    root, rot = np.array([0.0, 0.95, 0.0]), quat.identity(17)
    wp, _ = _world(sk, root, rot)
    elbow = sk.index("r_lower_arm")
    goal_q = quat.from_axis_angle([0, 1, 0], 0.4)
    res = solve_ik(rig, root, rot,
                   [Effector(elbow, wp[elbow] + [0.0, 0.05, 0.1]), Effector("head", orientation=goal_q)],
                   [Pin("l_foot"), Pin("r_foot")])  # fmt: skip
    assert res.reached
    wp2, wr2 = _world(sk, res.root, res.rotations)
    assert np.linalg.norm(wp2[elbow] - (wp[elbow] + [0.0, 0.05, 0.1])) < 1e-3
    assert quat.angle_between(wr2[sk.index("head")], goal_q) < 5e-3


def test_stiffness_shifts_motion_to_softer_joints():
    joints = 4
    sk = chain_skeleton(joints)
    rot = quat.exp(np.tile([0.3, 0.0, 0.0], (joints, 1)))
    target = [0.1, 0.2, 0.1]

    def moved(stiff):
        rig = IKRig.build(sk, stiffness=stiff)
        c0, _ = rig.to_coordinates(np.zeros(3), rot)
        res = solve_ik(rig, np.zeros(3), rot, [Effector(joints - 1, target, point=TIP)])
        assert res.reached
        return np.linalg.norm((res.coordinates - c0).reshape(joints, 3), axis=1)

    soft, stiff = moved({}), moved({"j1": 20.0})
    assert stiff[1] < 0.3 * soft[1]
    assert stiff[2] > soft[2]


def test_bad_input_raises_clear_errors():
    sk = chain_skeleton(4)
    rig = IKRig.build(sk)
    rot = quat.identity(4)
    with pytest.raises(ValueError, match="at least one effector"):
        solve_ik(rig, np.zeros(3), rot, [])
    with pytest.raises(ValueError, match="finite"):
        solve_ik(rig, np.zeros(3), rot, [Effector(3, [np.nan, 0, 0])])
    with pytest.raises(ValueError, match="neither"):
        solve_ik(rig, np.zeros(3), rot, [Effector(3)])
    with pytest.raises(KeyError, match="no joint"):
        solve_ik(rig, np.zeros(3), rot, [Effector("tail", [0, 0, 0])])
