"""Two-bone IK with a pole on the hip–target line, in a batch: that puppet gets no swivel, as if alone.

A pole on the line through the hip and the target names no side; the solve then keeps the bend plane
it found (no swivel) rather than turning towards the rounding residue of the pole's direction. Each
puppet decides that for itself: a neighbour with a proper pole changes nothing. Shown to fail by
mutation (docs/mutation.md, sixth round): the pole's "off the line" test taken over the whole batch
(``np.linalg.norm(v, axis=None)`` or no axis) lets the neighbour's pole vouch for it, and the puppet
swivels by whatever angle the residue points at.
"""

from __future__ import annotations

import numpy as np

from engine.fk import forward_kinematics
from engine.humanoid import humanoid_skeleton
from engine.ik import two_bone_ik
from engine.pose import Pose

LEG = ("l_upper_leg", "l_lower_leg", "l_foot")


def test_a_pole_on_the_hip_target_line_gives_no_swivel_whatever_the_neighbours() -> None:
    sk = humanoid_skeleton()
    ia, ib, ic = (sk.index(j) for j in LEG)
    pose = Pose.rest(sk, 2)
    wp = forward_kinematics(sk, pose.root, pose.rotations)[0]
    a, c = wp[:, ia], wp[:, ic]
    targets = a + (c - a) * 0.8 + np.array([0.05, 0.0, 0.1])
    poles = np.stack([a[0] + 2.0 * (targets[0] - a[0]), a[1] + np.array([0.0, -0.4, 1.0])])
    line = poles[0] - a[0]
    off = line - np.dot(line, targets[0] - a[0]) / np.dot(targets[0] - a[0], targets[0] - a[0]) * (targets[0] - a[0])
    assert np.linalg.norm(off) < 1e-12  # the pole is on the line (to rounding)

    both = Pose.rest(sk, 2)
    reached = two_bone_ik(sk, both, LEG, targets, poles)
    np.testing.assert_allclose(reached, targets, atol=1e-9)
    alone = Pose.rest(sk, 1)
    two_bone_ik(sk, alone, LEG, targets[:1], poles[:1])
    np.testing.assert_allclose(both.rotations[0], alone.rotations[0], atol=1e-12)
    knee = forward_kinematics(sk, both.root, both.rotations)[0][:, ib]
    assert knee[1, 2] - a[1, 2] > 0.05  # the neighbour's knee does face its pole (forward)
