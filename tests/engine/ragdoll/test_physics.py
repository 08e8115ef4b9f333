"""PhysicsWorld.drive_animated over command columns: the whole crowd at once (one array write)
commands exactly what driving each puppet alone does, and a bad target is refused per puppet."""

from __future__ import annotations

import numpy as np
import pytest

from engine import quat
from engine.ragdoll import PhysicsWorld, default_profile
from engine.skeleton import Skeleton


def _world(skeleton: Skeleton, n: int) -> PhysicsWorld:
    pw = PhysicsWorld()
    rot = quat.identity(skeleton.num_joints)
    for k in range(1, n + 1):
        pw.add_ragdoll(k, skeleton, default_profile(skeleton), [2.0 * k, 1.0, 0.0], rot)
    return pw


def test_driving_the_whole_crowd_commands_what_driving_each_puppet_does(skeleton: Skeleton) -> None:
    """Broken once by writing the crowd's rows in the order given, not in key order (keys passed
    backwards): the targets landed on the wrong puppets and this failed."""
    n, j = 4, skeleton.num_joints
    rng = np.random.default_rng(3)
    roots = rng.normal(size=(n, 3))
    rots = quat.normalize(rng.normal(size=(n, j, 4)))
    whole, one = _world(skeleton, n), _world(skeleton, n)
    assert whole.drive_animated([1, 2, 3, 4], roots, rots) == []
    for k in (4, 2, 3, 1):  # one at a time, in another order
        assert one.drive_animated([k], roots[k - 1 : k], [rots[k - 1]]) == []
    backwards = _world(skeleton, n)
    backwards.drive_animated([4, 3, 2, 1], roots[::-1], list(rots[::-1]))
    for k in range(1, n + 1):
        for pw in (one, backwards):
            np.testing.assert_array_equal(pw.target(k).root, whole.target(k).root)
            np.testing.assert_array_equal(pw.target(k).rotations, whole.target(k).rotations)
    np.testing.assert_array_equal(whole.target(3).root, roots[2])


def test_a_bad_target_is_refused_for_that_puppet_alone(skeleton: Skeleton) -> None:
    n, j = 3, skeleton.num_joints
    pw = _world(skeleton, n)
    before = pw.target(2)
    roots = np.zeros((n, 3))
    rots = np.tile(quat.identity(j), (n, 1, 1))
    rots[1, 5, 0] = np.nan
    assert pw.drive_animated([1, 2, 3], roots, rots) == [2]
    np.testing.assert_array_equal(pw.target(2).root, before.root)
    np.testing.assert_array_equal(pw.target(1).root, roots[0])
    with pytest.raises(KeyError, match="entity 9"):
        pw.drive_animated([1, 9], roots[:2], rots[:2])
