"""The snowman rig: bone lengths from ball sizes, and the Bézier spine of Eq. 6.4."""

import numpy as np
import pytest

from engine import quat
from engine.fk import forward_kinematics, world_points
from games.snowman.rig import SnowmanShape, bezier_spine, middle_ball_parameter, snowman_skeleton, spine_control_point


def standing(shape):
    sk = snowman_skeleton(shape)
    pos, rot = forward_kinematics(sk, sk.offsets[0], quat.identity(sk.num_joints))
    return sk, pos, rot


def test_balls_stack_on_each_other_and_head_size_sets_neck():
    shape = SnowmanShape(0.5, 0.35, 0.22)
    sk, pos, rot = standing(shape)
    hips, chest, head = pos[sk.index("hips")], pos[sk.index("chest")], pos[sk.index("head")]
    assert np.linalg.norm(chest - hips) == pytest.approx(0.5 + 2 * 0.35)  # chest on top of the middle ball
    assert np.linalg.norm(head - chest) == pytest.approx(0.22)  # the head ball rests on it
    t = middle_ball_parameter(shape)
    up = chest  # standing upright: the Bézier is the straight spine
    middle = bezier_spine(hips, chest, up, t)
    assert np.linalg.norm(middle - hips) == pytest.approx(0.5 + 0.35)
    bigger_head = snowman_skeleton(SnowmanShape(0.5, 0.35, 0.3))
    assert np.linalg.norm(bigger_head.offsets[sk.index("neck")]) > np.linalg.norm(sk.offsets[sk.index("neck")])
    toes = world_points(sk, pos, rot)[sk.index("l_foot")]
    assert abs(toes[1]) < 0.02  # feet on the ground
    assert pos[sk.index("hips")][1] - shape.bottom < 0.1  # the bottom ball sits on the snow


def test_two_ball_snowman():
    sk, pos, _ = standing(SnowmanShape(0.4, None, 0.25))
    assert pos[sk.index("head")][1] > pos[sk.index("hips")][1] + 0.4


def test_wrong_order_or_bad_radius_refused():
    with pytest.raises(ValueError, match="largest"):
        SnowmanShape(0.2, 0.3, 0.1)
    with pytest.raises(ValueError, match="positive"):
        SnowmanShape(0.5, float("nan"), 0.1)


def test_bezier_spine_formula_and_endpoints():
    p0, p2, up = np.array([0, 1.0, 0]), np.array([0.6, 1.6, 0]), np.array([0, 1.85, 0])
    p1 = spine_control_point(p0, p2, up, 0.3)
    np.testing.assert_allclose(p1, (p0 + 0.7 * p2 + 0.3 * up) / 2)
    pts = bezier_spine(p0, p2, up, np.linspace(0, 1, 5))
    np.testing.assert_allclose(pts[0], p0)
    np.testing.assert_allclose(pts[-1], p2)
    np.testing.assert_allclose(pts[2], 0.25 * p0 + 0.5 * p1 + 0.25 * p2)


def test_bent_spine_bows_toward_upright():
    """With the chest pushed sideways the curve's middle lies between the straight line and upright."""
    p0, p2, up = np.array([0, 1.0, 0]), np.array([0.8, 1.4, 0]), np.array([0, 1.9, 0])
    mid = bezier_spine(p0, p2, up, 0.5)
    straight_mid = (p0 + p2) / 2
    assert mid[1] > straight_mid[1]  # bows up toward the upright chest
    assert mid[0] < straight_mid[0]
