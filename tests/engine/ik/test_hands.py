"""Palms on a snowball: on its surface, facing it, on the side towards the character; the spine leans when needed."""

from __future__ import annotations

import numpy as np
import pytest

from engine import quat
from engine.fk import forward_kinematics
from engine.humanoid import humanoid_skeleton
from engine.ik import HUMANOID_ARMS, hands_on_sphere, sphere_contacts
from engine.pose import Pose


def _palms(sk, pose):
    wp, wr = forward_kinematics(sk, pose.root, pose.rotations)
    out = []
    for arm in HUMANOID_ARMS:
        h = sk.index(arm.hand)
        out.append((wp[h] + quat.rotate(wr[h], arm.palm), quat.rotate(wr[h], arm.palm_normal)))
    return out


@pytest.mark.parametrize(("centre", "radius"), [((0.0, 0.9, 0.45), 0.2), ((0.05, 0.65, 0.45), 0.25)])
def test_palms_on_the_surface_facing_the_centre(centre, radius):
    sk = humanoid_skeleton()
    pose = Pose.rest(sk)
    centre = np.array(centre)
    hands_on_sphere(sk, pose, centre, radius)
    (lp, ln), (rp, rn) = _palms(sk, pose)
    for p, n in ((lp, ln), (rp, rn)):
        assert abs(np.linalg.norm(p - centre) - radius) < 3e-3
        assert np.dot(n, (centre - p) / np.linalg.norm(centre - p)) > 0.99
        assert p[2] < centre[2]  # the near side of the ball
    assert lp[0] > rp[0]  # left hand on the left
    assert pose.is_finite()


def test_low_ball_makes_the_spine_lean_forward():
    sk = humanoid_skeleton()
    pose = Pose.rest(sk)
    hands_on_sphere(sk, pose, [0.0, 0.35, 0.55], 0.35)
    wp, _ = forward_kinematics(sk, pose.root, pose.rotations)
    assert wp[sk.index("chest")][2] > 0.05
    lean = quat.angle_between(pose.rotations[sk.index("spine")], quat.identity())
    assert 0.05 < lean <= 0.9 + 1e-9


def test_contacts_are_symmetric_and_bad_spheres_rejected():
    pts, normals = sphere_contacts([0, 0.5, 1.0], 0.3, [0, 1.2, 0], [1, 0, 0])
    assert np.allclose(np.linalg.norm(pts - [0, 0.5, 1.0], axis=1), 0.3)
    assert pts[0, 0] == pytest.approx(-pts[1, 0]) and np.all(normals[:, 2] < 0)
    with pytest.raises(ValueError, match="positive radius"):
        hands_on_sphere(humanoid_skeleton(), Pose.rest(humanoid_skeleton()), [0, 0, 1], 0.0)
