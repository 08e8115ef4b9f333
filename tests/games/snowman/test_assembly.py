"""Snowman assembly rules (``games.snowman.assembly.find_snowmen``): what stack is a snowman.

Each rule below is one the demo never exercises; each test was shown to fail with the rule broken:
equal radii accepted (``radii[:, None] < radii[None, :]`` made ``<=``), a stack off the ground
accepted (the ``on_ground`` check removed), four-ball snowmen (``len(stack) < 3`` made ``< 4``).
"""

from __future__ import annotations

import numpy as np

from games.snowman.assembly import Ball, find_snowmen


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
