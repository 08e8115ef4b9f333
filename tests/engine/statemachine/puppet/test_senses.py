"""What a puppet perceives: the facing rotation of a crowd, written out, against the generic one.

Shown to fail when broken: the written-out ``x``/``z`` parts as ``np.zeros_like(s)`` instead of
``s * 0.0`` (a heading of ``-0.0`` then loses the sign of its zero, and the state hash its bits)."""

import numpy as np
import pytest

from engine import quat
from engine.statemachine.puppet.senses import yaw_rotation


@pytest.mark.parametrize("scale", [1e-300, 1e-8, 1.0, 3.2, 100.0, 1e6])
def test_the_crowd_facing_has_the_bits_of_from_axis_angle(scale: float) -> None:
    headings = np.random.default_rng(0).normal(size=1001) * scale
    headings[:5] = [0.0, -0.0, np.pi, -np.pi, np.nan]
    fast = yaw_rotation(headings)
    generic = quat.from_axis_angle(np.array([0.0, 1.0, 0.0]), headings)
    assert fast.shape == generic.shape == (1001, 4)
    assert fast.tobytes() == generic.tobytes()


def test_one_heading_is_one_quaternion() -> None:
    assert yaw_rotation(np.pi / 2) == pytest.approx([np.cos(np.pi / 4), 0.0, np.sin(np.pi / 4), 0.0])
