"""Resampling at warped times: exact at keys, periodic across the seam."""

from __future__ import annotations

import numpy as np

from authoring.mocurves import periodic_cubic, periodic_slerp, retime_clip
from engine import quat


def test_periodic_cubic_is_exact_at_keys_and_wraps():
    t = np.arange(12) / 12
    v = np.stack([np.sin(2 * np.pi * t), np.cos(2 * np.pi * t)], axis=1)
    np.testing.assert_allclose(periodic_cubic(v, 1.0, t), v, atol=1e-12)
    np.testing.assert_allclose(periodic_cubic(v, 1.0, t + 3.0), v, atol=1e-12)
    mid = periodic_cubic(v, 1.0, [0.5 / 12])
    np.testing.assert_allclose(mid[0], [np.sin(np.pi / 12), np.cos(np.pi / 12)], atol=5e-4)  # O(h⁴) at 12 keys


def test_periodic_slerp_crosses_the_seam():
    q = quat.from_axis_angle([0, 1, 0], np.arange(8) * 0.1)
    out = periodic_slerp(q, 8.0, [7.5, -0.5])
    expected = quat.slerp(q[7], q[0], 0.5)
    assert np.all(quat.angle_between(out, expected[None]) < 1e-7)


def test_identity_times_give_the_clip_back(walk):
    t = np.arange(walk.num_frames) / walk.fps
    clip, _ = retime_clip(walk, t)
    np.testing.assert_allclose(clip.root, walk.root, atol=1e-12)
    assert np.max(quat.angle_between(clip.rotations, walk.rotations)) < 1e-7
    np.testing.assert_allclose(clip.root_motion.translation, walk.root_motion.translation, atol=1e-12)
