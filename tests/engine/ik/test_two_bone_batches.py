"""Two-bone IK through its public call only, on batches with more than one leading axis.

Written against ``two_bone_ik``'s contract (reach the target or stretch towards it, keep bone
lengths, bend towards the pole, blend by weight, every puppet solved as if alone), not its
internals, so it holds for any implementation. Checked by mutation (docs/mutation.md): a norm over
``axis=+1`` instead of the last axis only differs on a ``[2, 3]`` batch and fails
``test_a_grid_of_puppets_solves_each_as_if_alone``; a straight-limb test that never fires fails
``test_straight_limbs_bend_and_reach``.
"""

from __future__ import annotations

import numpy as np
import pytest

from engine import quat
from engine.fk import forward_kinematics
from engine.humanoid import humanoid_skeleton
from engine.ik import two_bone_ik
from engine.pose import Pose
from engine.skeleton import Skeleton

LEG = ("l_upper_leg", "l_lower_leg", "l_foot")
ARM = ("l_upper_arm", "l_lower_arm", "l_hand")
F = np.ndarray


def world(sk: Skeleton, pose: Pose, offsets: F | None = None) -> F:
    return forward_kinematics(sk, pose.root, pose.rotations, offsets)[0]


def random_grid(sk: Skeleton, shape: tuple[int, ...], seed: int) -> tuple[Pose, F]:
    rng = np.random.default_rng(seed)
    pose = Pose.rest(sk, int(np.prod(shape)))
    pose.rotations[:] = quat.exp(rng.uniform(-0.5, 0.5, (*pose.rotations.shape[:-1], 3)))
    pose.root[:] = rng.uniform([-1, 0.8, -1], [1, 1.0, 1], pose.root.shape)
    offsets = np.broadcast_to(sk.offsets, (*pose.rotations.shape[:-2], *sk.offsets.shape)).copy()
    offsets *= rng.uniform(0.8, 1.2, (*pose.rotations.shape[:-2], 1, 1))
    grid = Pose(root=pose.root.reshape(*shape, 3), rotations=pose.rotations.reshape(*shape, *pose.rotations.shape[-2:]))
    return grid, offsets.reshape(*shape, *sk.offsets.shape)


@pytest.mark.parametrize("limb", [LEG, ARM])
@pytest.mark.parametrize("with_pole,with_end,weight", [(True, False, 1.0), (False, True, 1.0), (True, True, "grid")])
def test_a_grid_of_puppets_solves_each_as_if_alone(
    limb: tuple[str, str, str], with_pole: bool, with_end: bool, weight: object
) -> None:
    sk = humanoid_skeleton()
    shape = (2, 3)
    grid, offsets = random_grid(sk, shape, seed=5)
    rng = np.random.default_rng(7)
    a = world(sk, grid, offsets)[..., sk.index(limb[0]), :]
    targets = a + rng.uniform(-0.9, 0.9, (*shape, 3))
    poles = a + rng.uniform(-1, 1, (*shape, 3)) if with_pole else None
    ends = quat.normalize(rng.normal(size=(*shape, 4))) if with_end else None
    w = rng.uniform(0.1, 0.9, shape) if weight == "grid" else np.ones(shape)
    solved = Pose(root=grid.root.copy(), rotations=grid.rotations.copy())
    got = two_bone_ik(
        sk, solved, limb, targets, poles, end_rotation=ends, offsets=offsets, weight=w if weight == "grid" else 1.0
    )
    assert got.shape == (*shape, 3)
    for i in np.ndindex(*shape):
        one = Pose(root=grid.root[i].copy(), rotations=grid.rotations[i].copy())
        end = two_bone_ik(
            sk,
            one,
            limb,
            targets[i],
            None if poles is None else poles[i],
            end_rotation=None if ends is None else ends[i],
            offsets=offsets[i],
            weight=float(w[i]),
        )
        np.testing.assert_allclose(quat.angle_between(one.rotations, solved.rotations[i]), 0.0, atol=1e-7)
        if weight == 1.0:
            np.testing.assert_allclose(got[i], end, atol=1e-9)


def test_every_puppet_reaches_its_target_or_stretches_towards_it() -> None:
    sk = humanoid_skeleton()
    shape = (3, 2)
    grid, offsets = random_grid(sk, shape, seed=9)
    ia, ib, ic = (sk.index(j) for j in LEG)
    before = world(sk, grid, offsets)
    a = before[..., ia, :]
    lab = np.linalg.norm(before[..., ib, :] - a, axis=-1)
    lbc = np.linalg.norm(before[..., ic, :] - before[..., ib, :], axis=-1)
    rng = np.random.default_rng(1)
    direction = quat.rotate(quat.normalize(rng.normal(size=(*shape, 4))), np.array([0.0, 0.0, 1.0]))
    reach = np.array([[0.5, 1.5], [0.9, 0.2], [1.2, 0.7]])  # of the leg's full length
    targets = a + direction * (reach * (lab + lbc))[..., None]
    poles = a + rng.normal(size=(*shape, 3))
    end = two_bone_ik(sk, grid, LEG, targets, poles, offsets=offsets)
    after = world(sk, grid, offsets)
    np.testing.assert_allclose(after[..., ic, :], end, atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(after[..., ib, :] - a, axis=-1), lab, atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(after[..., ic, :] - after[..., ib, :], axis=-1), lbc, atol=1e-9)
    dist = np.linalg.norm(end - a, axis=-1)
    lo, hi = np.abs(lab - lbc), lab + lbc
    within = (np.linalg.norm(targets - a, axis=-1) > lo) & (np.linalg.norm(targets - a, axis=-1) < hi)
    np.testing.assert_allclose(end[within], targets[within], atol=1e-9)
    np.testing.assert_allclose(
        dist[~within], np.clip(np.linalg.norm(targets - a, axis=-1), lo + 1e-6, hi - 1e-6)[~within], atol=1e-6
    )
    aim = (end - a) / dist[..., None]
    np.testing.assert_allclose(aim, direction, atol=1e-9)  # out of reach: straight towards it
    # the knee bends towards the pole's side of the a → target line
    knee = after[..., ib, :] - a
    side = poles - a
    knee_off = knee - np.sum(knee * aim, axis=-1, keepdims=True) * aim
    pole_off = side - np.sum(side * aim, axis=-1, keepdims=True) * aim
    bent = np.linalg.norm(knee_off, axis=-1) > 1e-4
    assert bent.sum() >= 3 and np.all(np.sum(knee_off * pole_off, axis=-1)[bent] > 0)


@pytest.mark.parametrize("limb,pole", [(LEG, None), (LEG, "on axis"), (ARM, None), (LEG, "front")])
def test_straight_limbs_bend_and_reach(limb: tuple[str, str, str], pole: str | None) -> None:
    """A limb at rest is straight (no bend plane of its own): the solve still reaches, batch and alone alike."""
    sk = humanoid_skeleton()
    rest = Pose.rest(sk, 4)
    wp = world(sk, rest)
    ia, ib, ic = (sk.index(j) for j in limb)
    a, c = wp[:, ia], wp[:, ic]
    full = np.linalg.norm(c - a, axis=-1)
    shrink = np.array([0.5, 0.7, 0.9, 0.99])[:, None]
    targets = a + (c - a) * shrink  # along the limb: only a bend can get there
    poles = {None: None, "on axis": a + (c - a) * 3.0, "front": a + np.array([0.0, 0.0, 1.0])}[pole]
    end = two_bone_ik(sk, rest, limb, targets, poles)
    np.testing.assert_allclose(end, targets, atol=1e-9)
    after = world(sk, rest)
    mid = after[:, ib]
    assert np.all(np.linalg.norm(np.cross(c - a, mid - a), axis=-1) > 1e-3 * full**2)  # it bent
    if pole == "front":
        assert np.all(mid[:, 2] > a[:, 2] + 1e-3)
    for i in range(4):
        one = Pose.rest(sk)
        two_bone_ik(sk, one, limb, targets[i], None if poles is None else poles[i])
        np.testing.assert_allclose(world(sk, one)[ic], targets[i], atol=1e-9)
        np.testing.assert_allclose(world(sk, one)[ib], mid[i], atol=1e-7)


def test_a_target_too_close_folds_the_limb_as_far_as_it_goes() -> None:
    sk = humanoid_skeleton()
    pose = Pose.rest(sk, 2)
    ia, ib, ic = (sk.index(j) for j in LEG)
    offsets = np.broadcast_to(sk.offsets, (2, *sk.offsets.shape)).copy()
    offsets[:, ic] *= [[0.5], [0.8]]  # shins shorter than thighs: the folded limb cannot reach its root
    wp = world(sk, pose, offsets)
    a = wp[:, ia]
    lab = np.linalg.norm(wp[:, ib] - a, axis=-1)
    lbc = np.linalg.norm(wp[:, ic] - wp[:, ib], axis=-1)
    targets = a + np.array([[0.0, 0.0, 1e-4], [0.0, -1e-5, 0.0]])
    end = two_bone_ik(sk, pose, LEG, targets, a + np.array([0.0, 0.0, 1.0]), offsets=offsets)
    np.testing.assert_allclose(np.linalg.norm(end - a, axis=-1), np.abs(lab - lbc) + 1e-6, atol=1e-9)
    np.testing.assert_allclose(world(sk, pose, offsets)[:, ic], end, atol=1e-9)
    assert np.all(np.isfinite(pose.rotations))


def test_a_chain_from_the_root_joint_solves() -> None:
    """A limb whose first joint is the skeleton's root has no parent rotation to undo."""
    sk = humanoid_skeleton()
    second = next(j for j in range(1, sk.num_joints) if sk.parents[j] == 0)
    third = next(j for j in range(sk.num_joints) if sk.parents[j] == second)
    joints = (0, second, third)
    grid, _ = random_grid(sk, (2, 2), seed=3)
    wp = world(sk, grid)
    a = wp[..., joints[0], :]
    targets = wp[..., joints[2], :] + np.array([0.02, -0.03, 0.01])
    solved = Pose(root=grid.root.copy(), rotations=grid.rotations.copy())
    end = two_bone_ik(sk, solved, joints, targets, a + np.array([0.0, 0.0, 1.0]))
    np.testing.assert_allclose(world(sk, solved)[..., joints[2], :], end, atol=1e-9)
    for i in np.ndindex(2, 2):
        one = Pose(root=grid.root[i].copy(), rotations=grid.rotations[i].copy())
        two_bone_ik(sk, one, joints, targets[i], a[i] + np.array([0.0, 0.0, 1.0]))
        np.testing.assert_allclose(quat.angle_between(one.rotations, solved.rotations[i]), 0.0, atol=1e-7)


def test_weight_blends_each_joint_between_the_input_and_the_solve() -> None:
    sk = humanoid_skeleton()
    grid, _ = random_grid(sk, (2, 2), seed=4)
    targets = world(sk, grid)[..., sk.index(LEG[0]), :] + np.array([0.1, -0.5, 0.2])
    full = Pose(root=grid.root.copy(), rotations=grid.rotations.copy())
    two_bone_ik(sk, full, LEG, targets)
    w = np.array([[0.0, 0.25], [0.5, 1.0]])
    part = Pose(root=grid.root.copy(), rotations=grid.rotations.copy())
    two_bone_ik(sk, part, LEG, targets, weight=w)
    for i in np.ndindex(2, 2):
        for j in (sk.index(n) for n in LEG):
            expected = quat.slerp(grid.rotations[i][j], full.rotations[i][j], w[i])
            assert quat.angle_between(part.rotations[i][j], expected) < 1e-7
    untouched = [j for j in range(sk.num_joints) if sk.names[j] not in LEG]
    np.testing.assert_array_equal(part.rotations[..., untouched, :], grid.rotations[..., untouched, :])
