"""Roles: clips refused with the reason, conformed to the blend space's conventions, feet planted."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from engine import quat
from engine.clip import Clip, RootMotion
from engine.cliplib.plant import plant_feet
from engine.cliplib.roles import RoleError, check_role, check_set, conform, normalise_role
from engine.clips import default_clips, foot_contacts, foot_sliding
from engine.clips.contacts import world_poses
from engine.humanoid import humanoid_skeleton

SK = humanoid_skeleton()


def _baked(clip: Clip, turn: float = 0.7) -> Clip:
    """A clip's root motion baked into its root track and turned: what a raw loop from ``cycle`` looks like."""
    pos, rot = world_poses(clip)
    q = quat.from_axis_angle(np.array([0.0, 1.0, 0.0]), np.float64(turn))
    rots = np.array(clip.rotations)
    rots[:, 0] = quat.mul(q, rot[:, 0])
    return replace(
        clip,
        root=quat.rotate(q, pos[:, 0]) + np.array([3.0, 0.0, -2.0]),
        rotations=rots,
        root_motion=None,
        markers={},
        name="raw",
    )


def test_role_names_normalise_and_bad_ones_are_refused() -> None:
    assert normalise_role("Crouch idle") == normalise_role("crouch-idle") == "crouch_idle"
    assert normalise_role("wave") == "wave"
    with pytest.raises(RoleError, match="not a name"):
        normalise_role("../walk")


def test_built_in_clips_fit_their_roles() -> None:
    clips = default_clips()
    for role, clip in clips.items():
        check_role(clip, role, SK)
    check_set(clips)


@pytest.mark.parametrize(
    ("clip", "role", "reason"),
    [
        ("idle", "walk", "no forward speed"),
        ("get_up", "walk", "must be a loop"),
        ("walk", "crouch_walk", "is standing"),
        ("crouch_walk", "walk", "is crouched"),
        ("walk", "idle", "ground speed of 1.30"),
    ],
)
def test_a_clip_that_does_not_fit_is_refused_with_the_reason(clip: str, role: str, reason: str) -> None:
    with pytest.raises(RoleError, match=reason):
        check_role(default_clips()[clip], role, SK)


def test_a_cycle_whose_seam_jumps_is_not_a_loop() -> None:
    walk = default_clips()["walk"]
    rot = np.array(walk.rotations)
    knee = SK.index("l_lower_leg")
    rot[-1, knee] = quat.mul(rot[-1, knee], quat.from_axis_angle(np.array([1.0, 0.0, 0.0]), np.radians(40.0)))
    with pytest.raises(RoleError, match=r"does not loop: .* at l_lower_leg"):
        check_role(replace(walk, rotations=rot), "walk", SK)


def test_a_clip_on_another_skeleton_is_refused_with_how_to_retarget() -> None:
    walk = default_clips()["walk"]
    other = SK.with_offsets(SK.offsets * 1.0)
    other = replace(other, names=tuple(f"x_{n}" for n in SK.names))
    with pytest.raises(RoleError, match="retarget"):
        check_role(replace(walk, skeleton=other), "walk", SK)


def test_set_order_is_checked() -> None:
    clips = default_clips()
    clips["walk"] = clips["run"]
    with pytest.raises(RoleError, match="walk .* must be slower than the run"):
        check_set(clips)


def test_conform_gives_forward_root_motion_and_heel_strike_markers() -> None:
    walk = default_clips()["walk"]
    raw = _baked(walk)
    check_role(raw, "walk", SK)
    out = conform(raw, "walk")
    assert out.name == "walk" and out.fps == 60.0 and out.loop
    rm = out.root_motion
    assert rm is not None and np.allclose(rm.heading, 0.0) and np.allclose(rm.translation[:, [0, 1]], 0.0)
    assert out.average_speed() == pytest.approx(walk.average_speed(), rel=0.02)
    # The built-in walk strikes left at 0 and right at 0.5; the conformed copy finds the same.
    assert out.markers["left_down"] == pytest.approx(0.0, abs=0.04) or out.markers["left_down"] > 0.96
    assert out.markers["right_down"] == pytest.approx(0.5, abs=0.04)
    # World motion is kept: the feet touch down as before and do not start sliding.
    assert foot_contacts(out).mean() == pytest.approx(foot_contacts(walk).mean(), abs=0.05)
    assert foot_sliding(out).max() < 0.01


def _at_rate(clip: Clip, frames: int) -> Clip:
    """One cycle of a root-motion loop sampled at ``frames`` per cycle, its travel baked into the root track."""
    t = np.arange(frames) * clip.duration / frames
    pose = clip.sample(t)
    travel = np.array([clip.sample_root_motion(float(x))[0] for x in t])
    return Clip("raw", clip.skeleton, frames / clip.duration, pose.root + travel, pose.rotations, loop=True)


@pytest.mark.parametrize("rate", [24.0, 30.0, 50.0, 120.0])
def test_a_loop_at_any_rate_is_conformed_at_its_speed_without_a_seam_pop(rate: float) -> None:
    walk = default_clips()["walk"]
    raw = _at_rate(walk, round(walk.duration * rate))
    out = conform(raw, "walk")
    assert out.fps == 60.0 and out.average_speed() == pytest.approx(walk.average_speed(), rel=0.01)
    # Root position continuous across the seam within one frame's travel (sway and bob stay in the root).
    seam = np.linalg.norm(out.root[0] - out.root[-1])
    assert seam <= walk.average_speed() / out.fps


def test_planting_removes_the_retargeted_mocap_skate(cmu_walk_loop: Clip) -> None:
    raw = conform(cmu_walk_loop, "idle")  # resampled and turned only, no planting
    from engine.cliplib.roles import _facing_travel, _with_travel_root_motion

    unplanted = _with_travel_root_motion(_facing_travel(raw))
    before = foot_sliding(unplanted, foot_contacts(unplanted, max_speed=0.6))
    planted = plant_feet(unplanted)
    after = foot_sliding(planted, foot_contacts(planted, max_speed=0.6))
    assert before.min() > 0.1  # the actor's feet on the puppet's legs creep ~0.15 m/s
    assert after.max() < 0.01
    # Pinning keeps the gait: both feet still stand about 60 % of the cycle, the speed is the actor's.
    assert np.all(np.abs(foot_contacts(planted).mean(axis=0) - 0.6) < 0.08)
    assert planted.average_speed() == pytest.approx(unplanted.average_speed())
    # And the whole pipeline (conform as a walk) is what clips add stores.
    walk = conform(cmu_walk_loop, "walk")
    check_role(walk, "walk", SK)
    assert 0.9 < walk.average_speed() < 1.3 and foot_sliding(walk).max() < 0.01


def _every(clip: Clip, k: int, n: int) -> Clip:
    """Frames ``0, k, 2k …`` (``n`` of them) of ``clip`` at ``fps / k``: the same cycle, fewer frames."""
    idx = np.arange(n) * k
    rm = clip.root_motion
    assert rm is not None
    return replace(
        clip,
        fps=clip.fps / k,
        root=clip.root[idx],
        rotations=clip.rotations[idx],
        root_motion=RootMotion(rm.translation[idx], rm.heading[idx]),
    )


def test_a_cycle_needs_at_least_eight_frames() -> None:
    """Shown to fail with the minimum lowered (``clip.num_frames < 8`` made ``< 7``) or removed: the
    7-frame walk (the built-in walk every 10th frame) then passes every other check."""
    walk = default_clips()["walk"]
    check_role(_every(walk, 9, 8), "walk", SK)  # eight frames: a cycle
    with pytest.raises(RoleError, match="has 7 frames; a walk cycle needs at least 8"):
        check_role(_every(walk, 10, 7), "walk", SK)


def test_a_walk_must_plant_both_feet_in_turn() -> None:
    """The left knee bent up through the whole walk: the left foot never touches the ground.

    Shown to fail with the contact check removed, or reduced to one foot (``not contacts[:, 0].any() or``
    dropped): the clip is then accepted as a walk."""
    walk = default_clips()["walk"]
    rot = np.array(walk.rotations)
    knee = SK.index("l_lower_leg")
    rot[:, knee] = quat.mul(quat.from_axis_angle(np.array([1.0, 0.0, 0.0]), np.radians(-90.0)), rot[:, knee])
    lame = replace(walk, rotations=rot, name="lame")
    assert foot_contacts(lame)[:, 1].any() and not foot_contacts(lame)[:, 0].any()
    with pytest.raises(RoleError, match="plants both feet in turn; in 'lame' the left foot never touches"):
        check_role(lame, "walk", SK)
    # The mirror image: the right foot up.
    rot = np.array(walk.rotations)
    knee = SK.index("r_lower_leg")
    rot[:, knee] = quat.mul(quat.from_axis_angle(np.array([1.0, 0.0, 0.0]), np.radians(-90.0)), rot[:, knee])
    with pytest.raises(RoleError, match="the right foot never touches"):
        check_role(replace(walk, rotations=rot, name="lame"), "walk", SK)
