"""The puppet plugin's pose overrides (:func:`apply_pose_overrides`): applied from the step their fields are
assigned, every step while they hold (the blend writes over the pose each step), and no longer once cleared."""

from __future__ import annotations

import numpy as np

from engine.components import LocalPose
from engine.pose import Pose
from engine.statemachine.puppet.body import PoseOverride
from engine.statemachine.puppet.plugin import apply_pose_overrides
from input.hub import InputHub
from puppetphone.games import make_app


def test_a_pose_override_is_applied_from_its_assignment_until_it_is_cleared() -> None:
    """Broken once by keeping the rows with an override without looking at the fields' assignment logs (the
    override assigned after the first pass was never applied): it failed."""
    app = make_app("sandbox", 0, InputHub([]), {"scene": "empty", "puppets": 3})
    app.run_steps(3)
    world = app.world
    es = sorted(int(e) for e, _ in world.query(PoseOverride))
    assert len(es) == 3
    roots = [world.get(e, LocalPose).root.copy() for e in es]
    apply_pose_overrides(world)  # nobody has an override: no pose changes
    assert all(np.array_equal(world.get(e, LocalPose).root, r) for e, r in zip(es, roots, strict=True))
    pose = world.get(es[1], LocalPose)
    held = Pose(np.array([0.1, 0.4, 0.2]), np.tile([0.0, 1.0, 0.0, 0.0], (len(pose.rotations), 1)))
    override = world.get(es[1], PoseOverride)
    override.pose, override.weight = held, 1.0
    apply_pose_overrides(world)
    assert np.array_equal(pose.root, held.root) and np.array_equal(pose.rotations, held.rotations)
    pose.root = np.zeros(3)  # what the blend does each step
    apply_pose_overrides(world)
    assert np.array_equal(pose.root, held.root)
    assert np.array_equal(world.get(es[0], LocalPose).root, roots[0])  # the others untouched
    override.weight = 0.0
    pose.root = np.zeros(3)
    apply_pose_overrides(world)
    assert np.array_equal(pose.root, np.zeros(3))
