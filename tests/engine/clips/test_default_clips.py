"""The seven default clips: valid data, closed loops, planted feet, believable speeds and shapes."""

from __future__ import annotations

import numpy as np
import pytest

import engine.clips as clips_pkg
from engine import quat
from engine.clips import CLIP_NAMES, LOCOMOTION, default_clips, foot_contacts, foot_sliding, sole_points, world_poses
from engine.fk import world_points

CLIPS = default_clips()
LOOPS = ("idle", "walk", "run", "crouch_idle", "crouch_walk")
SPEEDS = {"walk": 1.3, "run": 3.0, "crouch_walk": 0.7}


def _angle_jumps(rot: np.ndarray) -> np.ndarray:
    """Largest joint rotation change between consecutive frames ``[F-1]`` (radians)."""
    return quat.angle_between(rot[1:], rot[:-1]).max(axis=1)


def test_public_surface() -> None:
    assert set(clips_pkg.__all__) >= {"CLIP_NAMES", "default_clips", "foot_contacts"}
    for name in clips_pkg.__all__:
        assert hasattr(clips_pkg, name)


def test_all_seven_clips_are_there_and_cached() -> None:
    assert tuple(CLIPS) == CLIP_NAMES
    again = default_clips()
    assert all(again[k] is CLIPS[k] for k in CLIP_NAMES)
    again["mine"] = CLIPS["idle"]
    assert "mine" not in default_clips()


@pytest.mark.parametrize("name", CLIP_NAMES)
def test_clip_data_is_valid(name: str) -> None:
    clip = CLIPS[name]
    assert clip.name == name
    assert clip.skeleton.num_joints == 17
    assert np.isfinite(clip.root).all() and np.isfinite(clip.rotations).all()
    np.testing.assert_allclose(np.linalg.norm(clip.rotations, axis=-1), 1.0, atol=1e-9)
    assert clip.loop == (name in LOOPS)
    assert clip.num_frames >= 2


@pytest.mark.parametrize("name", LOOPS)
def test_loops_close(name: str) -> None:
    clip = CLIPS[name]
    rot = clip.rotations
    inside = _angle_jumps(rot).max()
    seam = quat.angle_between(rot[0], rot[-1]).max()
    assert seam <= inside + 1e-9, f"seam jump {np.degrees(seam):.2f}° > largest inside {np.degrees(inside):.2f}°"
    steps = np.linalg.norm(np.diff(clip.root, axis=0), axis=1).max()
    assert np.linalg.norm(clip.root[0] - clip.root[-1]) <= steps + 1e-9
    # The world motion closes too: frame F (next cycle's first) continues frame F-1.
    pos, _ = world_poses(clip, closing=True)
    jumps = np.linalg.norm(np.diff(pos, axis=0), axis=-1).max(axis=1)
    assert jumps[-1] <= jumps[:-1].max() + 1e-9


@pytest.mark.parametrize("name", LOCOMOTION)
def test_locomotion_speed_markers_and_heel_strikes(name: str) -> None:
    clip = CLIPS[name]
    assert clip.markers == {"left_down": 0.0, "right_down": 0.5}
    assert clip.average_speed() == pytest.approx(SPEEDS[name], rel=0.03)
    travel, heading = clip.cycle_travel()
    assert abs(heading) < 1e-9 and abs(travel[0]) < 1e-9 and travel[2] > 0  # straight ahead along +Z
    c = foot_contacts(clip)
    n = clip.num_frames
    starts = [np.nonzero(c[:, s] & ~np.roll(c[:, s], 1))[0].tolist() for s in range(2)]
    assert starts[0] == [0], f"left foot should touch down at phase 0, touches at frames {starts[0]}"
    assert starts[1] == [n // 2], f"right foot should touch down at phase 0.5, touches at frames {starts[1]}"


@pytest.mark.parametrize("name", LOCOMOTION)
def test_feet_do_not_slide_while_planted(name: str) -> None:
    slide = foot_sliding(CLIPS[name])
    assert np.all(slide < 0.02), f"{name} feet slide {slide} m/s"


@pytest.mark.parametrize("name", ("idle", "crouch_idle"))
def test_standing_feet_never_move(name: str) -> None:
    clip = CLIPS[name]
    assert foot_contacts(clip).all()
    assert np.all(foot_sliding(clip) < 1e-6)
    soles = sole_points(clip)
    assert np.ptp(soles, axis=0).max() < 1e-6
    assert clip.average_speed() == 0.0


def test_gait_phases_walk_double_support_run_flight() -> None:
    walk = foot_contacts(CLIPS["walk"])
    run = foot_contacts(CLIPS["run"])
    assert (walk[:, 0] & walk[:, 1]).any() and (walk[:, 0] | walk[:, 1]).all()
    assert not (run[:, 0] & run[:, 1]).any() and (~run[:, 0] & ~run[:, 1]).any()
    for c, lo, hi in ((walk, 0.55, 0.7), (run, 0.28, 0.42)):
        assert lo < c.mean() < hi  # stance fraction of the cycle


@pytest.mark.parametrize("name", CLIP_NAMES)
def test_feet_stay_above_ground(name: str) -> None:
    assert sole_points(CLIPS[name])[..., 1].min() > -0.01


@pytest.mark.parametrize("name", CLIP_NAMES)
def test_no_body_part_goes_through_the_floor(name: str) -> None:
    clip = CLIPS[name]
    pos, rot = world_poses(clip)
    tips = world_points(clip.skeleton, pos, rot)
    assert min(pos[..., 1].min(), tips[..., 1].min()) > -0.01


@pytest.mark.parametrize("name", CLIP_NAMES)
def test_knees_bend_forward_only(name: str) -> None:
    clip = CLIPS[name]
    for side in ("l", "r"):
        q = quat.align_hemisphere(clip.rotations[:, clip.skeleton.index(f"{side}_lower_leg")])
        assert np.all(q[:, 1] >= -1e-9), "knee flexes backwards"
        assert np.abs(q[:, 2:]).max() < 1e-9, "knee rotates off its hinge axis"
        assert np.all(2 * np.arctan2(q[:, 1], q[:, 0]) < np.radians(160))


def test_crouches_are_lower_than_standing() -> None:
    hips = {k: CLIPS[k].root[:, 1].mean() for k in CLIP_NAMES}
    assert hips["crouch_walk"] == pytest.approx(0.60, abs=0.03)
    assert hips["crouch_idle"] == pytest.approx(0.55, abs=0.03)
    for crouch in ("crouch_idle", "crouch_walk"):
        for stand in ("idle", "walk", "run"):
            assert hips[crouch] < hips[stand] - 0.2


def test_walk_arms_swing_against_the_legs() -> None:
    clip = CLIPS["walk"]
    pos, _ = world_poses(clip)
    j = clip.skeleton.index
    for f, forward_leg in ((0, "l"), (clip.num_frames // 2, "r")):
        back_arm = forward_leg
        front_arm = "r" if forward_leg == "l" else "l"
        assert pos[f, j(f"{forward_leg}_foot"), 2] > pos[f, j(f"{front_arm}_foot"), 2]
        assert pos[f, j(f"{front_arm}_hand"), 2] > pos[f, j(f"{back_arm}_hand"), 2] + 0.1


def test_idle_breathes_and_shifts_weight() -> None:
    clip = CLIPS["idle"]
    pos, _ = world_poses(clip)
    assert 0.01 < np.ptp(clip.root[:, 0]) < 0.06  # weight shift side to side
    chest = quat.angle_between(
        clip.rotations[:, clip.skeleton.index("chest")], clip.rotations[:1, clip.skeleton.index("chest")]
    )
    assert np.degrees(chest.max()) > 0.5  # breathing
    assert np.ptp(pos[:, clip.skeleton.index("head"), 1]) < 0.03  # but no bouncing


def test_get_up_goes_from_lying_to_idle() -> None:
    clip, idle = CLIPS["get_up"], CLIPS["idle"]
    assert 1.8 <= clip.duration <= 2.6
    pos, _ = world_poses(clip)
    j = clip.skeleton.index
    torso = pos[0, j("neck")] - pos[0, j("hips")]
    assert pos[0, 0, 1] < 0.25 and abs(torso[1]) < 0.1 * np.linalg.norm(torso)  # lying flat
    assert torso[2] < 0 and pos[0, j("l_foot"), 2] > pos[0, 0, 2]  # head towards -Z, feet towards +Z
    end = quat.angle_between(clip.rotations[-1], idle.rotations[0])
    assert np.degrees(end.max()) < 2.0
    np.testing.assert_allclose(clip.root[-1], idle.root[0], atol=0.01)
    assert clip.root_motion is not None and clip.cycle_travel()[0][2] > 0.2  # rose over feet ahead
    assert foot_contacts(clip)[-20:].all()
    assert np.all(foot_sliding(clip) < 0.05)


def test_mid_jump_is_an_airborne_tuck() -> None:
    clip = CLIPS["mid_jump"]
    assert 0.2 <= clip.duration <= 0.8
    assert not foot_contacts(clip).any()
    pos, _ = world_poses(clip)
    j = clip.skeleton.index
    for side in ("l", "r"):
        knee = quat.to_axis_angle(clip.rotations[:, j(f"{side}_lower_leg")])[1]
        assert np.degrees(knee.min()) > 60.0
        assert np.all(pos[:, j(f"{side}_hand"), 1] > pos[:, j("head"), 1])  # arms thrown up
        out = 1.0 if side == "l" else -1.0  # and apart, not crossed over the head
        assert np.all(out * (pos[:, j(f"{side}_hand"), 0] - pos[:, j(f"{side}_upper_arm"), 0]) > 0.05)
    assert np.all(pos[:, j("l_foot"), 1] > 0.25)
