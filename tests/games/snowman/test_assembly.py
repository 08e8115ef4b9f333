"""Snowman assembly rules (``games.snowman.assembly.find_snowmen``): what stack is a snowman.

Each rule below is one the demo never exercises; each test was shown to fail with the rule broken:
equal radii accepted (``radii[:, None] < radii[None, :]`` made ``<=``), a stack off the ground
accepted (the ``on_ground`` check removed), four-ball snowmen (``len(stack) < 3`` made ``< 4``).
"""

from __future__ import annotations

import numpy as np

from games.snowman.assembly import Ball, find_snowmen, resting_matrix


def _stack(radii: list[float], x: float = 0.0, lift: float = 0.0, first_id: int = 1) -> list[Ball]:
    """Balls stacked straight up, touching, the lowest ``lift`` m above the ground."""
    balls, y = [], lift
    for k, r in enumerate(radii):
        balls.append(Ball(first_id + k, np.array([x, y + r, 0.0]), r))
        y += 2 * r
    return balls


def ids(stacks: list[list[Ball]]) -> list[list[int]]:
    return [[b.entity for b in s] for s in stacks]


def test_equal_radii_are_not_a_snowman() -> None:
    """A ball on a ball of the same size is not a body and a head: the head must be smaller."""
    assert find_snowmen(_stack([0.4, 0.4])) == []
    assert ids(find_snowmen(_stack([0.4, 0.3, 0.3]))) == [[1, 2]]  # the equal third ball is not its head
    assert ids(find_snowmen(_stack([0.4, 0.39]))) == [[1, 2]]  # just smaller is enough


def test_a_stack_that_does_not_stand_on_the_ground_is_not_a_snowman() -> None:
    """Held up in the air, or resting on something else, it waits until it stands on the ground."""
    assert find_snowmen(_stack([0.5, 0.35, 0.2], lift=0.5)) == []
    assert find_snowmen(_stack([0.5, 0.35, 0.2], lift=0.11)) == []  # just past the 0.1 m allowance
    assert ids(find_snowmen(_stack([0.5, 0.35, 0.2], lift=0.09))) == [[1, 2, 3]]


def test_a_snowman_has_at_most_three_balls() -> None:
    """A fourth ball on the head is not part of the snowman (and alone is no snowman of its own)."""
    stacks = find_snowmen(_stack([0.5, 0.35, 0.2, 0.1]))
    assert ids(stacks) == [[1, 2, 3]]
    assert all(len(s) <= 3 for s in stacks)
    # Two stacks side by side: each is its own snowman, both read from the ground up.
    both = find_snowmen(_stack([0.5, 0.3], x=0.0) + _stack([0.6, 0.4, 0.25], x=3.0, first_id=10))
    assert sorted(ids(both)) == [[1, 2], [10, 11, 12]]


def test_resting_means_touching_and_above_not_beside_or_floating() -> None:
    """``resting_matrix``: on top = centre above, within ``off_axis`` of the lower radius horizontally,
    surfaces touching within ``gap``. Found by the mutation run: ``gap``/``off_axis`` changed, the
    conditions joined with ``|``, ``gap * touch`` made ``gap / touch`` survived the tests above."""
    lower, r = np.array([0.0, 0.5, 0.0]), 0.3
    touch = 0.5 + r

    def on(upper: np.ndarray) -> bool:
        return bool(resting_matrix(np.array([upper, lower]), np.array([r, 0.5]))[0, 1])

    straight_up = lower + np.array([0.0, touch, 0.0])
    assert on(straight_up)
    assert on(lower + np.array([0.0, 1.04 * touch, 0.0]))  # a little snow between: within the gap
    assert not on(lower + np.array([0.0, 1.1 * touch, 0.0]))  # floating a hand's breadth above
    assert not on(lower + np.array([0.0, 1.075 * touch, 0.0]))  # the gap is 6 % of the radii's sum
    assert not on(lower + np.array([0.0, 0.9 * touch, 0.0]))  # sunk into it: not a stack
    for frac, expected in ((0.3, True), (0.44, True), (0.6, False), (0.9, False)):
        h = frac * 0.5  # horizontally off by a fraction of the lower radius, still touching
        upper = lower + np.array([h, np.sqrt(touch**2 - h**2), 0.0])
        assert on(upper) is expected, frac
    assert not bool(resting_matrix(np.array([lower, straight_up]), np.array([0.5, r]))[0, 1])  # below is not on


def test_the_choice_between_balls_does_not_depend_on_the_order_they_are_listed() -> None:
    """Two heads on one body: the lower entity id is the head. A ball touching two bodies goes to one of
    them, the lower. Found by the mutation run: choosing by list position (``min(above)`` without the key,
    the bases unsorted or sorted by another axis) or letting a used ball join a second stack survived."""
    import itertools

    body = Ball(1, np.array([0.0, 0.5, 0.0]), 0.5)
    touch = 0.5 + 0.2
    heads = [Ball(e, np.array([x, 0.5 + np.sqrt(touch**2 - x**2), 0.0]), 0.2) for e, x in ((7, 0.1), (3, -0.1))]
    for order in itertools.permutations([body, *heads]):
        assert ids(find_snowmen(list(order))) == [[1, 3]]
    # One ball resting on two bodies standing close together: one snowman, each ball in it once, built on
    # the lower body (stacks are read from the ground up), whatever the ids and the list order.
    a = Ball(10, np.array([-0.05, 0.5, 0.05]), 0.5)
    b = Ball(9, np.array([0.05, 0.52, -0.05]), 0.5)
    top = Ball(12, np.array([0.0, 0.51 + np.sqrt(touch**2 - 0.05**2), 0.0]), 0.2)
    assert resting_matrix(np.array([top.center, a.center, b.center]), np.array([0.2, 0.5, 0.5]))[0, 1:].all()
    for order in itertools.permutations([top, b, a]):
        assert ids(find_snowmen(list(order))) == [[10, 12]]


def test_a_ball_held_low_in_the_air_does_not_hide_a_snowman() -> None:
    """A small ball held just off the ground is lower than a big snowman's body centre; it is skipped,
    and the snowman is still found. Found by the mutation run (``continue`` made ``break`` survived)."""
    held = Ball(1, np.array([3.0, 0.3, 0.0]), 0.1)  # its bottom 0.2 m up
    snowman = _stack([0.5, 0.3], first_id=5)
    assert ids(find_snowmen([held, *snowman])) == [[5, 6]]
