"""Blending honours the optional translation and scale channels, and costs nothing without them."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from engine.blend.pose_blend import blend, crossfade
from engine.blend.space import BlendSpace
from engine.clips import default_clips
from engine.pose import Pose


def test_blend_and_crossfade_mix_offsets_and_scales() -> None:
    rot = np.tile([1.0, 0, 0, 0], (3, 1))
    a = Pose(np.zeros(3), rot, offsets=np.zeros((3, 3)), scales=np.ones(3))
    b = Pose(np.ones(3), rot, offsets=np.ones((3, 3)), scales=np.full(3, 3.0))
    mid = blend([0.25, 0.75], [a, b])
    assert np.allclose(mid.offsets, 0.75) and np.allclose(mid.scales, 2.5)
    half = crossfade(a, b, 0.5)
    assert np.allclose(half.offsets, 0.5) and np.allclose(half.scales, 2.0)
    plain = Pose(np.zeros(3), rot)
    assert blend([0.5, 0.5], [plain, plain]).offsets is None  # nothing to pay for without channels
    assert np.allclose(crossfade(plain, Pose(np.zeros(3), rot, scales=np.full(3, 2.0)), 0.5).scales, 1.5)
    with pytest.raises(ValueError, match="some poses carry joint offsets"):
        blend([0.5, 0.5], [plain, a])


def test_a_blend_space_blends_a_stretching_clip_with_a_rigid_one() -> None:
    clips = default_clips()
    walk, run = clips["walk"], clips["run"]
    run = run.resampled(walk.fps) if run.fps != walk.fps else run
    sk = walk.skeleton
    j = sk.index("l_lower_leg")
    stretched = walk.offsets()
    stretched[:, j] *= 1.2
    space = BlendSpace(
        (replace(walk, translations=stretched, scales=np.full((walk.num_frames, sk.num_joints), 2.0)), run),
        np.array([[0.0], [1.0]]),
        ("speed",),
    )
    pose = space.sample(np.array([0.5, 0.5]), 0.25)
    assert pose.offsets is not None and pose.scales is not None
    assert np.allclose(pose.offsets[j], sk.offsets[j] * 1.1) and np.allclose(pose.scales, 1.5)
    rigid = BlendSpace((walk, run), np.array([[0.0], [1.0]]), ("speed",)).sample(np.array([0.5, 0.5]), 0.25)
    assert rigid.offsets is None and rigid.scales is None
