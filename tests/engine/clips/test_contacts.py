"""Foot contacts and sliding are measured in the world, with root motion applied."""

from __future__ import annotations

import numpy as np
import pytest

from engine import quat
from engine.clip import Clip
from engine.clips import foot_contacts, foot_sliding, sole_points
from engine.humanoid import humanoid_skeleton


def _rest_clip(root: np.ndarray, loop: bool = False) -> Clip:
    sk = humanoid_skeleton()
    return Clip("test", sk, 60.0, root, quat.identity(len(root), sk.num_joints), loop)


def test_standing_still_is_in_contact_and_does_not_slide() -> None:
    clip = _rest_clip(np.tile([0.0, 0.95, 0.0], (30, 1)))
    c = foot_contacts(clip)
    assert c.shape == (30, 2) and c.dtype == bool and c.all()
    np.testing.assert_allclose(foot_sliding(clip), 0.0, atol=1e-12)
    soles = sole_points(clip)
    np.testing.assert_allclose(soles[..., 1], 0.01, atol=1e-9)  # rest sole is 1 cm up


def test_lifted_puppet_has_no_contact() -> None:
    clip = _rest_clip(np.tile([0.0, 1.4, 0.0], (10, 1)))
    assert not foot_contacts(clip).any()
    np.testing.assert_allclose(foot_sliding(clip), 0.0)


def test_sliding_feet_are_measured_at_their_speed() -> None:
    t = np.arange(60) / 60.0
    root = np.stack([np.zeros(60), np.full(60, 0.95), 0.2 * t], axis=-1)  # skating at 0.2 m/s
    clip = _rest_clip(root)
    assert foot_contacts(clip).all()
    np.testing.assert_allclose(foot_sliding(clip), 0.2, rtol=1e-6)
    fast = _rest_clip(root * np.array([1.0, 1.0, 10.0]))  # 2 m/s: too fast to be standing
    assert not foot_contacts(fast).any()


def test_root_motion_counts_as_travel() -> None:
    # The same skate expressed as root motion: the in-place pose is still, the world is not.
    t = np.arange(60) / 60.0
    root = np.stack([np.zeros(60), np.full(60, 0.95), 0.2 * t], axis=-1)
    clip = _rest_clip(root).extract_root_motion()
    assert np.allclose(clip.root[:, 2], 0.0)
    np.testing.assert_allclose(foot_sliding(clip), 0.2, rtol=1e-6)


def test_contacts_of_wrong_shape_are_rejected() -> None:
    clip = _rest_clip(np.tile([0.0, 0.95, 0.0], (5, 1)))
    with pytest.raises(ValueError, match="contacts"):
        foot_sliding(clip, np.ones((4, 2), dtype=bool))
