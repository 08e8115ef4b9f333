"""Keyframed clips: exact Bézier sampling, fitting the built-in clips, baking to ordinary clips."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from engine.clips import default_clips
from engine.fk import forward_kinematics
from engine.keyframes import BezierCurves, KeyframedClip, bezier_basis, default_keyframed_clips


def _curve(a: float, b: float, ya: float = 0.3, yb: float = -0.2) -> BezierCurves:
    return BezierCurves([0.0, 1.0], [[0.0], [1.0]], [[a], [0.0]], [[ya], [0.0]], [[0.0], [b]], [[0.0], [yb]])


@settings(max_examples=60, deadline=None)
@given(st.floats(0.0, 1.0), st.floats(0.0, 1.0), st.floats(0.0, 1.0))
def test_sampling_inverts_the_time_curve_exactly(a, b, t):
    """For any time tangents within the key spacing, B^X(λ(t)) = t to machine precision."""
    c = _curve(a, b)
    _, lam = c.parameter([t])
    h0, tp, h1, tm = bezier_basis(lam)
    x = tp * a + h1 * 1.0 + tm * b
    assert abs(float(x[0, 0]) - t) < 1e-13
    assert 0.0 <= lam[0, 0] <= 1.0


def test_third_tangents_sample_the_cubic_polynomial():
    c = _curve(1 / 3, 1 / 3, 0.3, -0.2)
    t = np.linspace(0, 1, 7)
    h0, tp, h1, tm = bezier_basis(t)
    assert np.allclose(c.sample(t)[:, 0], h1 + 0.3 * tp - 0.2 * tm, atol=0, rtol=1e-15)


def test_bad_curves_are_refused():
    with pytest.raises(ValueError, match="Eq. 4.7"):
        _curve(1.5, 0.1)
    with pytest.raises(ValueError, match="increasing"):
        BezierCurves([0.0, 0.0], [[0.0], [1.0]], *([[[0.0], [0.0]]] * 4))


@pytest.mark.parametrize("name", sorted(default_clips()))
def test_builtin_clips_as_keyframes_bake_back_close(name):
    """Every built-in clip keyed every 3 frames bakes back to its frames (a cubic per segment meets 4 frames)."""
    clip = default_clips()[name]
    kc = default_keyframed_clips()[name]
    baked = kc.bake()
    assert baked.num_frames == clip.num_frames and baked.loop == clip.loop
    p0, _ = forward_kinematics(clip.skeleton, clip.root, clip.rotations)
    p1, _ = forward_kinematics(baked.skeleton, baked.root, baked.rotations)
    assert np.abs(p1 - p0).max() < 1e-6
    # keys are hit exactly
    keys = np.rint(kc.curves.times * clip.fps).astype(int) % clip.num_frames
    assert np.allclose(p1[keys], p0[keys], atol=1e-12)
    assert isinstance(kc, KeyframedClip)
