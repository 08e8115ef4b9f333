"""Two-bone IK against the law of cosines, with poles, stretching, batching and weights."""

from __future__ import annotations

import numpy as np
import pytest

from engine import quat
from engine.fk import forward_kinematics
from engine.humanoid import humanoid_skeleton
from engine.ik import two_bone_ik
from engine.pose import Pose

LEG = ("l_upper_leg", "l_lower_leg", "l_foot")
ARM = ("l_upper_arm", "l_lower_arm", "l_hand")


def _positions(sk, pose):
    wp, _ = forward_kinematics(sk, pose.root, pose.rotations)
    return wp


def test_known_triangle_matches_law_of_cosines():
    sk = humanoid_skeleton()
    pose = Pose.rest(sk)
    hip = _positions(sk, pose)[sk.index("l_upper_leg")]
    d = 0.6  # thigh and shin are 0.42 each
    target = hip + np.array([0.0, -d, 0.0])
    end = two_bone_ik(sk, pose, LEG, target, pole=hip + np.array([0.0, 0.0, 1.0]))
    wp = _positions(sk, pose)
    a, b, c = wp[sk.index("l_upper_leg")], wp[sk.index("l_lower_leg")], wp[sk.index("l_foot")]
    assert np.allclose(c, target, atol=1e-9) and np.allclose(end, target, atol=1e-9)
    knee = np.arccos(np.dot(a - b, c - b) / (np.linalg.norm(a - b) * np.linalg.norm(c - b)))
    assert knee == pytest.approx(np.arccos((0.42**2 + 0.42**2 - d**2) / (2 * 0.42 * 0.42)), abs=1e-9)
    assert np.linalg.norm(b - a) == pytest.approx(0.42) and np.linalg.norm(c - b) == pytest.approx(0.42)
    # the knee went towards the pole (forward), by the triangle's height
    assert b[2] == pytest.approx(np.sqrt(0.42**2 - (d / 2) ** 2), abs=1e-9)


def test_pole_chooses_the_bend_side_for_elbows():
    sk = humanoid_skeleton()
    pose = Pose.rest(sk)
    sh = _positions(sk, pose)[sk.index("l_upper_arm")]
    target = sh + np.array([0.0, -0.2, 0.3])
    two_bone_ik(sk, pose, ARM, target, pole=sh + np.array([0.3, -0.2, -1.0]))
    wp = _positions(sk, pose)
    elbow = wp[sk.index("l_lower_arm")]
    mid = (sh + target) / 2
    assert np.allclose(wp[sk.index("l_hand")], target, atol=1e-9)
    assert elbow[2] < mid[2]  # bends backward, towards the pole


def test_unreachable_target_stretches_towards_it():
    sk = humanoid_skeleton()
    pose = Pose.rest(sk)
    hip = _positions(sk, pose)[sk.index("l_upper_leg")]
    target = hip + np.array([0.0, -0.5, 1.5])
    end = two_bone_ik(sk, pose, LEG, target, pole=hip + [0.0, 0.0, 1.0])
    direction = (target - hip) / np.linalg.norm(target - hip)
    assert np.allclose(end, hip + 0.84 * direction, atol=1e-5)
    assert np.all(np.isfinite(pose.rotations))


def test_batched_equals_one_by_one_and_weight_blends():
    sk = humanoid_skeleton()
    rng = np.random.default_rng(3)
    hip = _positions(sk, Pose.rest(sk))[sk.index("l_upper_leg")]
    targets = hip + rng.uniform([-0.2, -0.8, -0.2], [0.2, -0.3, 0.3], size=(6, 3))
    pole = hip + np.array([0.0, 0.0, 1.0])
    batch = Pose.rest(sk, 6)
    two_bone_ik(sk, batch, LEG, targets, pole)
    for i in range(6):
        one = Pose.rest(sk)
        two_bone_ik(sk, one, LEG, targets[i], pole)
        assert np.allclose(one.rotations, batch.rotations[i], atol=1e-12)
    still = Pose.rest(sk)
    two_bone_ik(sk, still, LEG, targets[0], pole, weight=np.float64(0.0))
    assert np.allclose(still.rotations, Pose.rest(sk).rotations)


def test_end_rotation_is_applied_and_bad_input_rejected():
    sk = humanoid_skeleton()
    pose = Pose.rest(sk)
    q = np.array([np.cos(0.2), np.sin(0.2), 0.0, 0.0])
    two_bone_ik(sk, pose, LEG, [0.09, 0.2, 0.1], end_rotation=q)
    _, wr = forward_kinematics(sk, pose.root, pose.rotations)
    assert np.allclose(wr[sk.index("l_foot")], q, atol=1e-9)
    with pytest.raises(ValueError, match="parent chain"):
        two_bone_ik(sk, pose, ("l_upper_leg", "l_foot", "l_lower_leg"), [0, 0, 0])
    with pytest.raises(ValueError, match="finite"):
        two_bone_ik(sk, pose, LEG, [np.nan, 0, 0])


@pytest.mark.parametrize("limb", [LEG, ARM])
def test_one_pose_float_path_matches_the_batched_solver(limb):
    """A single pose is solved on floats (engine.ik._limb); it must agree with the numpy batch row by row."""
    sk = humanoid_skeleton()
    rng = np.random.default_rng(11)
    n = 12
    batch = Pose.rest(sk, n)
    batch.rotations[:] = quat.exp(rng.uniform(-0.6, 0.6, (n, 17, 3)))
    batch.rotations[0, sk.index(limb[1])] = quat.identity()  # a straight limb: the bend plane comes from the pole
    batch.root[:] = rng.uniform([-1, 0.8, -1], [1, 1.0, 1], (n, 3))
    offsets = np.broadcast_to(sk.offsets * rng.uniform(0.8, 1.2), (n, 17, 3)).copy()
    a = forward_kinematics(sk, batch.root, batch.rotations, offsets)[0][:, sk.index(limb[0])]
    targets = a + rng.uniform(-0.9, 0.9, (n, 3))  # some out of reach, some folded
    poles = a + rng.uniform(-1, 1, (n, 3))
    ends = quat.normalize(rng.normal(size=(n, 4)))
    for pole, end, weight in ((poles, None, 1.0), (None, ends, 1.0), (poles, ends, 0.4)):
        solved = batch.copy()
        reached = two_bone_ik(sk, solved, limb, targets, pole, end_rotation=end, offsets=offsets, weight=weight)
        for i in range(n):
            one = Pose(batch.root[i].copy(), batch.rotations[i].copy())
            p, q = None if pole is None else pole[i], None if end is None else end[i]
            got = two_bone_ik(sk, one, limb, targets[i], p, end_rotation=q, offsets=offsets[i], weight=weight)
            assert np.allclose(got, reached[i], atol=1e-10)
            assert np.allclose(one.rotations, solved.rotations[i], atol=1e-10)
