"""The animation stage's kept groups (:mod:`engine.blend._groups`): the same objects while nothing changes,
rebuilt on a structural change or a new set name, and a replaced foot lock noticed."""

from __future__ import annotations

import numpy as np

from engine.batches import batch
from engine.blend._groups import Groups
from engine.blend.locomotion import LocomotionPlayer
from engine.components import LocalPose, Puppet, Transform
from engine.ecs import World
from engine.humanoid import humanoid_skeleton
from engine.ik.foot_lock import FootLock
from engine.ik.system import IKRequest

_TYPES = ((Transform, Puppet, LocomotionPlayer), (LocalPose, IKRequest))


def _world(n: int) -> World:
    world = World(seed=1)
    sk = humanoid_skeleton()
    for i in range(n):
        parts = [Transform(np.array([float(i), 0.0, 0.0])), Puppet(sk), LocomotionPlayer(), IKRequest()]
        if i != 2:
            parts.append(LocalPose(np.zeros(3), np.tile([1.0, 0.0, 0.0, 0.0], (sk.num_joints, 1))))
        world.spawn(*parts)
    return world


def test_groups_are_kept_split_by_set_and_rebuilt_on_changes() -> None:
    """Broken once by keeping the groups whatever the set names (the snowman row stayed a humanoid): it failed."""
    world = _world(5)
    groups = Groups()
    first = groups.of(batch(world, "t", *_TYPES))
    assert [g.key for g in first] == ["humanoid"] and first[0].poses is None  # entity 3 has no pose yet
    assert groups.of(batch(world, "t", *_TYPES)) is first
    world.get(4, LocomotionPlayer).library_key = "snowman"
    split = groups.of(batch(world, "t", *_TYPES))
    assert [(g.key, g.entities) for g in split] == [("humanoid", [1, 2, 3, 5]), ("snowman", [4])]
    world.add(3, LocalPose(np.zeros(3), np.zeros((humanoid_skeleton().num_joints, 4))))
    again = groups.of(batch(world, "t", *_TYPES))
    assert again[0].poses is not None and again[0].poses[2] is world.get(3, LocalPose)


def test_a_replaced_foot_lock_is_handed_out() -> None:
    """Broken once by returning the kept tuple without the identity check: it failed."""
    world = _world(3)
    group = Groups().of(batch(world, "t", *_TYPES))[0]
    locks = group.foot_locks()
    assert group.foot_locks() is locks
    world.get(2, IKRequest).foot_lock = FootLock()
    assert group.foot_locks()[1] is world.get(2, IKRequest).foot_lock
