"""Blend spaces: gradient-band weights and what the blended clips play."""

from __future__ import annotations

import numpy as np
import pytest

from engine import quat
from engine.blend import PUPPET_PLACEMENT, BlendSpace, gradient_band_weights, measure_locomotion, puppet_blend_space
from engine.clip import Clip

RNG = np.random.default_rng(3)
FIG63 = np.array(list(PUPPET_PLACEMENT.values()))


@pytest.mark.parametrize("points", [FIG63, RNG.random((7, 3)), RNG.random((4, 1))])
def test_weights_sum_to_one_are_non_negative_and_exact_at_samples(points: np.ndarray) -> None:
    q = RNG.random((500, points.shape[1])) * 1.4 - 0.2
    w = gradient_band_weights(points, q)
    assert np.all(w >= 0.0)
    assert np.allclose(w.sum(axis=-1), 1.0)
    assert np.allclose(gradient_band_weights(points, points), np.eye(len(points)))


@pytest.mark.parametrize("points", [FIG63, RNG.random((7, 3))])
def test_weights_are_continuous(points: np.ndarray) -> None:
    n = points.shape[1]
    a = RNG.random((300, n))
    direction = RNG.normal(size=(300, n))
    direction /= np.linalg.norm(direction, axis=-1, keepdims=True)
    jumps = []
    for eps in (1e-3, 1e-5):
        d = np.abs(gradient_band_weights(points, a + eps * direction) - gradient_band_weights(points, a)).max()
        jumps.append(d)
    # a continuous (piecewise smooth) map shrinks its change with the step
    assert jumps[1] < jumps[0] / 30
    assert jumps[1] < 1e-3


def test_figure_6_3_example_weights(clips: dict[str, Clip]) -> None:
    space = puppet_blend_space(clips)
    assert space.names == tuple(PUPPET_PLACEMENT)
    w = space.weights(np.array([0.25, 1.0]))
    assert np.allclose(w, [0.5, 0.5, 0, 0, 0])  # halfway from idle to walk, nothing else
    w = space.weights(np.array([0.2, 0.73]))
    assert w[0] > w[1] > 0 and w[3] > 0 and w[2] == 0  # the green point of Fig. 6.3: run stays out


def test_sample_at_a_clip_point_plays_that_clip(clips: dict[str, Clip]) -> None:
    space = puppet_blend_space(clips)
    phase = np.array([0.3])
    pose = space.sample(space.weights(np.array([[1.0, 1.0]])), phase)
    t = space.sync.clip_times(phase)[0, 2]
    ref = clips["run"].sample(t)
    assert np.allclose(pose.root[0], ref.root)
    assert np.allclose(np.abs(np.sum(pose.rotations[0] * ref.rotations, axis=-1)), 1.0)


@pytest.mark.parametrize("height", [0.0, 0.5, 1.0])
def test_blended_speed_is_monotonic_along_the_velocity_axis(clips: dict[str, Clip], height: float) -> None:
    space = puppet_blend_space(clips)
    probes = np.stack([np.linspace(0.0, 1.0, 41), np.full(41, height)], axis=-1)
    speed = measure_locomotion(space, probes)[:, 0]
    assert np.all(np.diff(speed) > 0.0)
    analytic = np.linalg.norm(space.average_velocity(space.weights(probes)), axis=-1)
    assert np.allclose(speed, analytic, rtol=1e-9)


def test_crouch_lowers_the_measured_height(clips: dict[str, Clip]) -> None:
    space = puppet_blend_space(clips)
    probes = np.stack([np.zeros(11), np.linspace(0.0, 1.0, 11)], axis=-1)
    height = measure_locomotion(space, probes)[:, 1]
    assert np.all(np.diff(height) > 0.0)


def test_bad_layouts_are_rejected(clips: dict[str, Clip]) -> None:
    two = (clips["walk"], clips["run"])
    with pytest.raises(ValueError, match=r"\[0, 1\]"):
        BlendSpace(two, np.array([[0.0], [1.5]]), ("v",))
    with pytest.raises(ValueError, match="share a point"):
        BlendSpace(two, np.array([[0.5], [0.5]]), ("v",))
    with pytest.raises(ValueError, match="one per clip"):
        BlendSpace(two, np.array([[0.0, 1.0]]), ("v",))
    with pytest.raises(KeyError, match="needs clips"):
        puppet_blend_space({"walk": clips["walk"]})
    space = BlendSpace(two, np.array([[0.0], [1.0]]), ("v",))
    with pytest.raises(ValueError, match="end in 1"):
        space.weights(np.array([0.1, 0.2]))


def test_mean_method_blends_like_nlerp_for_close_poses(clips: dict[str, Clip]) -> None:
    two = (clips["walk"], clips["run"])
    a = BlendSpace(two, np.array([[0.0], [1.0]]), ("v",))
    b = BlendSpace(two, np.array([[0.0], [1.0]]), ("v",), method="mean")
    w = a.weights(np.array([[0.3]]))
    pa, pb = a.sample(w, np.array([0.2])), b.sample(w, np.array([0.2]))
    assert np.all(quat.angle_between(pa.rotations, pb.rotations) < 1e-2)


def test_root_only_sampling_matches_full_sampling(clips: dict[str, Clip]) -> None:
    space = puppet_blend_space(clips)
    p = np.random.default_rng(5).random((20, 2))
    phase = np.linspace(0.0, 2.5, 20)
    w = space.weights(p)
    assert np.allclose(space.sample_root(w, phase), space.sample(w, phase).root, atol=1e-12)
