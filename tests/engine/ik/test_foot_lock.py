"""Foot locks: the crowd's array pass and one puppet's pass lock the same feet the same way."""

from __future__ import annotations

import numpy as np

from engine import quat
from engine.humanoid import humanoid_skeleton
from engine.ik import PlaneGround, ground_feet
from engine.ik.foot_lock import FootLock
from engine.ik.grounding import ground_feet_batch
from engine.pose import Pose


def _poses(step: int, count: int) -> list[Pose]:
    """Puppets drifting forward and turning a little each step, legs bent differently."""
    sk = humanoid_skeleton()
    out = []
    for p in range(count):
        pose = Pose.rest(sk)
        pose.root[:] = [0.3 * p + 0.003 * step, 0.93, 0.004 * step]
        pose.rotations[0] = quat.from_axis_angle([0.0, 1.0, 0.0], 0.02 * step + 0.4 * p)
        pose.rotations[sk.index("l_upper_leg")] = quat.from_axis_angle([1.0, 0.0, 0.0], -0.2 - 0.05 * p)
        out.append(pose)
    return out


def test_the_crowd_pass_locks_as_one_puppet_at_a_time_does():
    sk = humanoid_skeleton()
    ground = PlaneGround()
    single = [FootLock() for _ in range(3)]
    batch = [FootLock() for _ in range(3)]
    held = []
    for step in range(12):
        contacts = np.array([1.0, 1.0 if step < 6 else 0.0])
        for lock in single + batch:
            lock.contacts = contacts
        one = _poses(step, 3)
        for pose, lock in zip(one, single, strict=True):
            ground_feet(sk, pose, ground, lock=lock, dt=1 / 60)
        many = _poses(step, 3)
        roots = np.array([p.root for p in many])
        rots = np.array([p.rotations for p in many])
        ground_feet_batch(sk, roots, rots, ground, locks=batch, dt=1 / 60)
        for k in range(3):
            assert np.allclose(roots[k], one[k].root, atol=1e-9)
            assert np.allclose(np.abs(np.sum(rots[k] * one[k].rotations, axis=-1)), 1.0, atol=1e-9)
            assert np.allclose(batch[k].points, single[k].points) and np.array_equal(
                batch[k].planted, single[k].planted
            )
        held.append(single[0].points[0].copy())
    # While the left foot is labelled down its lock stays where it landed although the body drifts.
    assert np.allclose(held[1], held[-1])
