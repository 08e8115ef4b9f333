"""Contacts from one stroke (§5.3): planted feet in the world, the root carrying the travel."""

from __future__ import annotations

import numpy as np
import pytest

from authoring.mocurves.contact import contact_runs, plane_from_stroke, solve_contacts
from engine.clips import world_poses
from engine.fk import forward_kinematics


def ground_stroke(clip, feet, lift=0.02):
    pos, _ = forward_kinematics(clip.skeleton, clip.root, clip.rotations)
    h = pos[:, feet, 1].min() + lift
    return plane_from_stroke([-1.0, h, 0.3], [1.0, h, 0.3], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0])


def test_stroke_plane_is_oriented_towards_the_root():
    plane = plane_from_stroke([0, 0.1, 0], [1, 0.1, 0], [0, 0, 1], [0, 1, 0])
    np.testing.assert_allclose(plane.normal, [0, 1, 0])
    assert plane.signed_distance([[0.5, 0.0, 2.0]])[0] == pytest.approx(-0.1)
    np.testing.assert_allclose(plane.project([0.5, 0.0, 2.0]), [0.5, 0.1, 2.0])
    with pytest.raises(ValueError, match="too short or parallel"):
        plane_from_stroke([0, 0, 0], [0, 0, 1], [0, 0, 1], [0, 1, 0])


def test_contact_runs_are_cyclic():
    m = np.array([1, 1, 0, 0, 1, 1, 0, 1], dtype=bool)
    assert sorted(contact_runs(m)) == [(4, 5), (7, 1)]
    assert contact_runs(np.zeros(5, bool)) == []
    with pytest.raises(ValueError, match="whole cycle"):
        contact_runs(np.ones(5, bool))


def test_contact_stroke_under_a_sliding_walk_plants_the_feet(sliding_walk):
    clip = sliding_walk
    sk = clip.skeleton
    feet = [sk.index("l_foot"), sk.index("r_foot")]
    before, _ = world_poses(clip, closing=True)
    result = solve_contacts(clip, feet, ground_stroke(clip, feet))
    pos, _ = world_poses(result.clip, closing=True)
    vel = np.diff(pos[:, feet], axis=0) * clip.fps  # [F,2,3], step f → f+1, the seam included
    old = np.diff(before[:, feet], axis=0) * clip.fps
    for i in range(2):
        c = result.contacts[:, i]
        steps = c & np.roll(c, -1)  # both ends of the step in contact
        assert 0.25 * len(c) < c.sum() < 0.75 * len(c)
        assert np.abs(vel[steps, i]).max() < 1e-9, "a planted foot moved in the world"
        assert np.linalg.norm(old[steps, i], axis=-1).mean() > 0.5, "the input walk did not slide"
        assert np.linalg.norm(vel[~c, i], axis=-1).max() > 1.0  # swing feet still swing
    # The two feet alternate: one is down while the other swings for most of the cycle.
    assert not np.all(result.contacts[:, 0] == result.contacts[:, 1])
    travel, _ = result.clip.cycle_travel()
    assert travel[2] > 1.0 and abs(travel[1]) < 1e-12  # the root walks forward, on the ground
    assert np.all(np.diff(result.clip.root_motion.translation[:, 2]) > 0)
    # Planted at the plane's height.
    plane_y = ground_stroke(clip, feet).point[1]
    assert np.allclose(pos[:-1][result.contacts[:, 0], feet[0], 1], plane_y, atol=1e-7)


def test_a_stroke_above_everything_or_nowhere_is_refused(sliding_walk):
    sk = sliding_walk.skeleton
    feet = [sk.index("l_foot"), sk.index("r_foot")]
    far_below = plane_from_stroke([-1, -5.0, 0], [1, -5.0, 0], [0, 0, -1], [0, 1, 0])
    with pytest.raises(ValueError, match="no item reaches"):
        solve_contacts(sliding_walk, feet, far_below)
    above = plane_from_stroke([-1, 3.0, 0], [1, 3.0, 0], [0, 0, -1], [0, 5, 0])  # all curves on the wrong side
    with pytest.raises(ValueError, match="whole cycle"):
        solve_contacts(sliding_walk, feet, above)
