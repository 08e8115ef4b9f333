"""Feet on slopes and steps: soles on the ground, feet turned to its normal, pelvis lowered for dips."""

from __future__ import annotations

import numpy as np
import pytest

from engine import quat
from engine.fk import forward_kinematics
from engine.humanoid import humanoid_skeleton
from engine.ik import HeightfieldGround, PlaneGround, ground_feet
from engine.pose import Pose

SOLE = np.array([0.0, -0.05, 0.075])


def _sole(sk, pose, foot):
    wp, wr = forward_kinematics(sk, pose.root, pose.rotations)
    f = sk.index(foot)
    return wp[f] + quat.rotate(wr[f], SOLE), wr[f]


def test_sole_lands_on_a_slope_and_aligns_with_it():
    sk = humanoid_skeleton()
    clip = Pose.rest(sk)
    clip_height = _sole(sk, clip, "l_foot")[0][1]  # the clip's sole clearance on flat ground
    ground = PlaneGround(point=(0.0, 0.0, 0.0), normal=(0.15, 1.0, -0.3))
    pose = clip.copy()
    ground_feet(sk, pose, ground)
    for foot in ("l_foot", "r_foot"):
        sole, rot = _sole(sk, pose, foot)
        h, n = ground(sole[0], sole[2])
        assert sole[1] - h == pytest.approx(clip_height, abs=2e-3)
        up = quat.rotate(rot, [0.0, 1.0, 0.0])
        assert np.degrees(np.arccos(np.clip(np.dot(up, n), -1, 1))) < 1.0
        wp, wr = forward_kinematics(sk, pose.root, pose.rotations)
        toe = wp[sk.index(foot)] + quat.rotate(wr[sk.index(foot)], [0.0, -0.05, 0.15])
        assert toe[1] - ground(toe[0], toe[2])[0] == pytest.approx(clip_height, abs=2e-3)
    assert pose.is_finite()


def test_dip_lowers_the_pelvis_and_step_bends_the_other_knee():
    sk = humanoid_skeleton()
    heights = np.zeros((5, 3))
    heights[3:, :] = -0.12  # the left foot (x = +0.09) stands in a flat dip, the right one (x = −0.09) on flat ground
    ground = HeightfieldGround(heights, cell=0.09, x0=-0.185, z0=-0.09)
    h, n = ground(np.array([0.09, -0.09]), np.array([0.0, 0.0]))
    assert np.allclose(h, [-0.12, 0.0]) and np.allclose(n[:, 1], 1.0)
    pose = Pose.rest(sk)
    shift = ground_feet(sk, pose, ground)
    assert shift == pytest.approx(-0.12, abs=1e-3)
    assert pose.root[1] == pytest.approx(0.95 - 0.12, abs=1e-3)
    left, _ = _sole(sk, pose, "l_foot")
    right, _ = _sole(sk, pose, "r_foot")
    clip = _sole(sk, Pose.rest(sk), "l_foot")[0][1]
    assert left[1] == pytest.approx(-0.12 + clip, abs=2e-3)
    assert right[1] == pytest.approx(clip, abs=2e-3)
    wp, _ = forward_kinematics(sk, pose.root, pose.rotations)
    assert wp[sk.index("r_lower_leg")][2] > 0.01  # the right knee bends forward to stay on the high ground


def test_lifted_foot_keeps_its_clearance_and_bad_ground_is_rejected():
    sk = humanoid_skeleton()
    pose = Pose.rest(sk)
    pose.rotations[sk.index("l_upper_leg")] = quat.from_axis_angle([1, 0, 0], -0.6)  # swing leg forward
    before = _sole(sk, pose, "l_foot")[0]
    ground_feet(sk, pose, PlaneGround(point=(0.0, 0.1, 0.0)))
    after = _sole(sk, pose, "l_foot")[0]
    assert after[1] - 0.1 == pytest.approx(before[1], abs=2e-3)
    with pytest.raises(ValueError, match="non-finite"):
        ground_feet(sk, Pose.rest(sk), lambda x, z: (np.full(np.shape(x), np.nan), np.zeros(np.shape(x) + (3,))))


def test_the_batched_grounding_agrees_with_one_puppet_at_a_time():
    from engine.ik.grounding import HeightfieldGround, ground_feet_batch

    sk = humanoid_skeleton()
    rng = np.random.default_rng(4)
    n = 6
    rots = quat.normalize(np.tile(quat.identity(sk.num_joints), (n, 1, 1)) + rng.normal(0, 0.08, (n, sk.num_joints, 4)))
    roots = np.column_stack([rng.uniform(-2, 2, n), np.full(n, 0.95), rng.uniform(-2, 2, n)])
    offsets = sk.offsets * rng.uniform(0.8, 1.2, (n, 1, 1))
    ground = HeightfieldGround(rng.uniform(-0.1, 0.1, (12, 12)), 0.5, -3.0, -3.0)
    weights = rng.uniform(0, 1, n)
    r, q = roots.copy(), rots.copy()
    shift = ground_feet_batch(sk, r, q, ground, offsets=offsets, weight=weights)
    for i in range(n):
        pose = Pose(roots[i].copy(), rots[i].copy())
        assert ground_feet(sk, pose, ground, offsets=offsets[i], weight=weights[i]) == pytest.approx(
            shift[i], abs=1e-12
        )
        np.testing.assert_allclose(pose.root, r[i], atol=1e-12)
        np.testing.assert_allclose(pose.rotations, q[i], atol=1e-12)
