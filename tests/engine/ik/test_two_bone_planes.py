"""Two-bone IK's bend plane, through the public call on one-axis batches.

Without a pole the solve keeps the plane the limb is already bent in, down to a bend of a few
millionths of its length; only a limb straight to that tolerance takes a plane of its own, and each
puppet of a batch decides that for itself. Shown to fail by mutation (docs/mutation.md, fifth round):
the straight-limb threshold ``1e-6 · lab·lcb`` made ``1e-6 / (lab·lcb)`` or ``1e-6 · lab/lcb`` (the
nearly straight leg bends sideways no more); the weak-fallback norm taken over the whole batch
(``axis=None``, no axis: the arm along x stays straight and misses); the weak fallback's axis
``[0, 0, 1]`` made ``[0, 1, 1]`` (the elbow leaves the forward plane); ``quat.identity(*shape[:+2])``
for a chain from the root joint (a one-axis batch no longer broadcasts).
"""

from __future__ import annotations

import numpy as np

from engine import quat
from engine.fk import forward_kinematics
from engine.humanoid import humanoid_skeleton
from engine.ik import two_bone_ik
from engine.pose import Pose
from engine.skeleton import Skeleton

LEG = ("l_upper_leg", "l_lower_leg", "l_foot")
ARM = ("l_upper_arm", "l_lower_arm", "l_hand")
F = np.ndarray


def world(sk: Skeleton, pose: Pose) -> F:
    return forward_kinematics(sk, pose.root, pose.rotations)[0]


def test_a_nearly_straight_leg_keeps_its_own_bend_plane() -> None:
    """The rest leg hangs straight down; bent sideways (about z) by a relative 4·10⁻⁶, it folds sideways.

    A limb straight to within the threshold would take the fallback plane instead (about x: the knee
    forward), which is what the mutants with a larger threshold do.
    """
    sk = humanoid_skeleton()
    ia, ib, ic = (sk.index(j) for j in LEG)
    rest = world(sk, Pose.rest(sk))
    lab = float(np.linalg.norm(rest[ib] - rest[ia]))
    lcb = float(np.linalg.norm(rest[ic] - rest[ib]))
    # |(c − a) × (b − a)| = lab·lcb·sin(bend) for a bend at the knee: 4× the straight threshold.
    bend = 4e-6
    pose = Pose.rest(sk, 2)
    pose.rotations[:, ib] = quat.from_axis_angle(np.array([0.0, 0.0, 1.0]), np.array([bend, -bend]))
    wp = world(sk, pose)
    a, b, c = wp[:, ia], wp[:, ib], wp[:, ic]
    normal = np.linalg.norm(np.cross(c - a, b - a), axis=-1)
    np.testing.assert_allclose(normal, lab * lcb * np.sin(bend), rtol=1e-3)
    side = np.sign(b[:, 0] - (a[:, 0] + (c[:, 0] - a[:, 0]) * lab / (lab + lcb)))  # which way the knee is off
    np.testing.assert_array_equal(side, [-1.0, 1.0])
    targets = a + (c - a) * 0.8
    end = two_bone_ik(sk, pose, LEG, targets)
    np.testing.assert_allclose(end, targets, atol=1e-9)
    knee = world(sk, pose)[:, ib] - a
    assert np.all(np.abs(knee[:, 2]) < 1e-9)  # no forward component: still in the x-y plane
    assert np.all(knee[:, 0] * side > 0.05)  # and well out to the side it was bent to


def test_each_puppet_of_a_batch_finds_its_own_fallback_plane() -> None:
    """One arm held out along x (its first fallback plane is degenerate), one hanging straight down.

    Without a pole a straight limb bends in the plane it makes with the forward axis z: the elbow
    moves forward or back, never up, down or sideways (the fallback for the arm along x made
    ``cross(c − a, [0, 1, 1])`` lifts the elbow out of that plane).
    """
    sk = humanoid_skeleton()
    ia, ib, ic = (sk.index(j) for j in ARM)
    pose = Pose.rest(sk, 2)
    pose.rotations[0, ia] = quat.from_axis_angle(np.array([0.0, 0.0, 1.0]), np.pi / 2)
    wp = world(sk, pose)
    a, c = wp[:, ia], wp[:, ic]
    along = (c - a) / np.linalg.norm(c - a, axis=-1, keepdims=True)
    np.testing.assert_allclose(along, [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0]], atol=1e-12)
    targets = a + (c - a) * 0.75
    end = two_bone_ik(sk, pose, ARM, targets)
    np.testing.assert_allclose(end, targets, atol=1e-9)
    after = world(sk, pose)
    np.testing.assert_allclose(after[:, ic], targets, atol=1e-9)
    assert np.all(np.linalg.norm(np.cross(c - a, after[:, ib] - a), axis=-1) > 1e-3)  # both bent
    np.testing.assert_allclose(after[0, ib, 1], a[0, 1], atol=1e-9)  # the arm along x: elbow at shoulder height
    np.testing.assert_allclose(after[1, ib, 0], a[1, 0], atol=1e-9)  # the hanging arm: no sideways move


def test_a_chain_from_the_root_joint_solves_on_a_one_axis_batch() -> None:
    sk = humanoid_skeleton()
    second = next(j for j in range(1, sk.num_joints) if sk.parents[j] == 0)
    third = next(j for j in range(sk.num_joints) if sk.parents[j] == second)
    joints = (0, second, third)
    pose = Pose.rest(sk, 3)
    pose.rotations[:, second] = quat.from_axis_angle(np.array([1.0, 0.0, 0.0]), np.array([0.2, 0.3, 0.4]))
    wp = world(sk, pose)
    targets = wp[:, third] + np.array([0.02, -0.03, 0.01])
    end = two_bone_ik(sk, pose, joints, targets, wp[:, 0] + np.array([0.0, 0.0, 1.0]))
    np.testing.assert_allclose(end, targets, atol=1e-9)
    np.testing.assert_allclose(world(sk, pose)[:, third], targets, atol=1e-9)
