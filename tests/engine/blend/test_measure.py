"""Playing and measuring blends: root speed, hips height, contacts and foot sliding."""

from __future__ import annotations

import numpy as np

from engine.blend import foot_slide, measure_locomotion, play, puppet_blend_space
from engine.blend.measure import blended_contacts
from engine.clip import Clip


def test_measured_speed_and_height_of_a_single_clip(clips: dict[str, Clip]) -> None:
    space = puppet_blend_space(clips)
    u = measure_locomotion(space, np.array([[0.5, 1.0], [0.0, 0.0]]))
    walk = clips["walk"]
    assert abs(u[0, 0] - walk.average_speed()) < 1e-9
    assert abs(u[0, 1] - walk.root[:, 1].mean()) < 2e-3
    assert u[1, 0] == 0.0 and abs(u[1, 1] - clips["crouch_idle"].root[:, 1].mean()) < 2e-3


def test_play_moves_by_root_motion_or_carried_velocity(clips: dict[str, Clip]) -> None:
    space = puppet_blend_space(clips)
    w = space.weights(np.array([[0.5, 1.0]]))
    pb = play(space, w, 120, 1.0 / 60.0)
    assert abs(pb.position[-1, 0, 2] / (119 / 60.0) - clips["walk"].average_speed()) < 0.05
    carried = play(space, w, 120, 1.0 / 60.0, carried=np.array([[0.0, 0.0, 3.0]]))
    assert np.allclose(carried.position[-1, 0], [0.0, 0.0, 3.0 * 119 / 60.0])


def test_blended_contacts_of_one_clip_are_its_labels(clips: dict[str, Clip]) -> None:
    space = puppet_blend_space(clips)
    walk = clips["walk"]
    n = walk.num_frames
    labels = np.zeros((n, 2), dtype=bool)
    labels[: n // 2, 0] = True
    tracks = [labels if c.name == "walk" else np.ones((c.num_frames, 2), dtype=bool) for c in space.clips]
    phase = (np.arange(n) + 0.25) / n
    got = blended_contacts(space, space.weights(np.array([0.5, 1.0])), phase, tracks)
    assert np.array_equal(got, labels)


def test_feet_slide_when_the_body_outruns_the_animation(clips: dict[str, Clip]) -> None:
    space = puppet_blend_space(clips)
    w = space.weights(np.array([[0.5, 1.0], [0.5, 1.0]]))
    speed = clips["walk"].average_speed()
    carried = np.array([[0.0, 0.0, speed], [0.0, 0.0, 2.0 * speed]])
    slide = foot_slide(space, play(space, w, 180, 1.0 / 60.0, carried=carried))
    assert slide[1] > slide[0] + 0.7 * speed
