"""Snowball growth by the snow picked up, marks in the field, and snowman recognition."""

import numpy as np
import pytest

from games.snowman.assembly import Ball, find_snowmen
from games.snowman.snow import SnowField, grow_radius, segment_area


def test_segment_area_limits():
    assert segment_area(0.3, 0.0) == 0.0
    assert segment_area(0.3, 0.3) == pytest.approx(np.pi * 0.3**2 / 2)  # sunk to the equator
    assert segment_area(0.3, 1.0) == segment_area(0.3, 0.3)


def test_ball_grows_by_volume_and_slower_when_big():
    r1 = grow_radius(0.1, 1.0, 0.04)
    assert r1 > 0.1

    def v(r):
        return 4 / 3 * np.pi * r**3

    assert v(r1) - v(0.1) == pytest.approx(segment_area(0.1, 0.04) * 1.0)
    # The same metre adds less radius to a big ball.
    assert grow_radius(0.5, 1.0, 0.04) - 0.5 < r1 - 0.1


def test_rolling_takes_snow_from_the_field_and_conserves_volume():
    field = SnowField(size=4.0, cell=0.05)
    before = field.depth.sum() * field.cell**2
    a, b = np.array([-1.0, 0, 0]), np.array([1.0, 0, 0])
    r = field.roll(a, b, 0.1)
    assert r > 0.13
    gained = 4 / 3 * np.pi * (r**3 - 0.1**3)
    taken = before - field.depth.sum() * field.cell**2
    assert gained == pytest.approx(taken, rel=1e-9)
    assert field.depth_at([0.0, 0, 0]) < 0.7 * 0.04  # a visible track
    assert field.depth_at([0.0, 0, 1.0]) == pytest.approx(0.04)  # off the track: untouched


def test_small_steps_grow_like_one_big_step():
    one, many = SnowField(size=4.0, cell=0.15), SnowField(size=4.0, cell=0.15)
    r_one = one.roll(np.array([-1.0, 0, 0]), np.array([1.0, 0, 0]), 0.1)
    r_many = 0.1
    xs = np.linspace(-1, 1, 171)
    for x0, x1 in zip(xs[:-1], xs[1:]):
        r_many = many.roll(np.array([x0, 0, 0]), np.array([x1, 0, 0]), r_many)
    assert r_many == pytest.approx(r_one, rel=0.1)


def test_rolling_the_same_strip_again_gives_less():
    field = SnowField(size=4.0, cell=0.05)
    a, b = np.array([-1.0, 0, 0]), np.array([1.0, 0, 0])
    r1 = field.roll(a, b, 0.1)
    r2 = field.roll(a, b, 0.1)
    assert r2 - 0.1 < 0.8 * (r1 - 0.1)


def test_three_stacked_balls_are_a_snowman_and_wrong_order_is_not():
    bottom = Ball(1, np.array([0, 0.5, 0]), 0.5)
    middle = Ball(2, np.array([0.05, 0.5 + 0.5 + 0.35, 0]), 0.35)
    head = Ball(3, np.array([0, 1.35 + 0.35 + 0.2, 0]), 0.2)
    loose = Ball(4, np.array([3, 0.2, 0]), 0.2)
    stacks = find_snowmen([head, loose, middle, bottom])
    assert [[b.entity for b in s] for s in stacks] == [[1, 2, 3]]
    big_on_small = Ball(5, np.array([3, 0.4 + 0.6, 0]), 0.6)
    small = Ball(6, np.array([3, 0.4, 0]), 0.4)
    assert find_snowmen([small, big_on_small]) == []
    beside = Ball(7, np.array([1.2, 0.5, 0]), 0.5)
    assert find_snowmen([bottom, beside]) == []
