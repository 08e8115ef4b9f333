"""Retargeting real mocap onto the puppet, and the joint-name maps."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from engine import quat
from engine.fk import forward_kinematics, world_points
from engine.humanoid import humanoid_skeleton
from engine.io.bvh import read_bvh
from engine.io.bvh_convert import detect_tpose_frames
from engine.io.joint_maps import JOINT_MAPS, guess_joint_map
from engine.io.retarget import retarget

PUPPET = humanoid_skeleton()


def _source(mocap_dir: Path, name: str):  # type: ignore[no-untyped-def]
    m = read_bvh(mocap_dir / name)
    return m.to_clip(skip_frames=detect_tpose_frames(m))


def _feet(clip):  # type: ignore[no-untyped-def]
    wpos, wrot = forward_kinematics(PUPPET, clip.root, clip.rotations)
    tips = world_points(PUPPET, wpos, wrot)
    out = []
    for name in ("l_foot", "r_foot"):
        j = PUPPET.index(name)
        out.append(np.minimum(wpos[:, j, 1], tips[:, j, 1]))
    return wpos, np.stack(out, axis=1)


@pytest.mark.parametrize("floor", [True, False])
def test_cmu_walk_plays_on_the_puppet(mocap_dir: Path, floor: bool) -> None:
    src = _source(mocap_dir, "cmu_16_15_walk_daz.bvh")
    clip = retarget(src, PUPPET, floor=floor)
    assert clip.skeleton is PUPPET and clip.num_frames == src.num_frames
    assert np.isfinite(clip.rotations).all() and np.isfinite(clip.root).all()
    wpos, feet = _feet(clip)
    # Every step (0.25 s window) brings a foot to the floor: within 3 cm when grounded, and within
    # ~5 cm from the leg-length scaling alone (DAZ ankles sit higher than the puppet's).
    win = int(0.25 * clip.fps)
    lowest = feet.min(axis=1)
    per_step = np.array([lowest[i : i + win].min() for i in range(0, len(lowest) - win, win)])
    assert np.all(np.abs(per_step) < (0.03 if floor else 0.06)), per_step
    # The walk travels forward (the file walks along +Z), about 1 m/s, upright, head above hips.
    travel = clip.root[-1] - clip.root[0]
    assert travel[2] > 3.0 and abs(travel[0]) < 0.3
    assert np.all(wpos[:, PUPPET.index("head"), 1] > wpos[:, 0, 1] + 0.4)
    # Both feet alternate: each is in front of the other for a good part of the time.
    ahead = wpos[:, PUPPET.index("l_foot"), 2] > wpos[:, PUPPET.index("r_foot"), 2]
    assert 0.3 < ahead.mean() < 0.7


def test_bone_directions_copy_the_source(mocap_dir: Path) -> None:
    # The defining property: each mapped bone points where the source bone points.
    for name in ("cmu_16_15_walk_daz.bvh", "bandai1_walk_normal_001.bvh", "cmu_02_01_walk_ccbase.bvh"):
        src = _source(mocap_dir, name)
        _, mapping, _ = guess_joint_map(src.skeleton.names)
        clip = retarget(src, PUPPET)
        s_pos, _ = forward_kinematics(src.skeleton, src.root, src.rotations)
        t_pos, _ = forward_kinematics(PUPPET, clip.root, clip.rotations)
        for a, b in (
            ("l_upper_arm", "l_lower_arm"),
            ("r_lower_arm", "r_hand"),
            ("l_upper_leg", "l_lower_leg"),
            ("r_lower_leg", "r_foot"),
            ("spine", "chest"),
        ):
            sa, sb = src.skeleton.index(mapping[a]), src.skeleton.index(mapping[b])
            if src.skeleton.parents[sb] != sa:
                continue  # joints skipped in between (iClone's Spine01) bend the source "bone"
            ds = s_pos[:, sb] - s_pos[:, sa]
            dt = t_pos[:, PUPPET.index(b)] - t_pos[:, PUPPET.index(a)]
            cos = np.sum(ds * dt, axis=1) / np.linalg.norm(ds, axis=1) / np.linalg.norm(dt, axis=1)
            assert cos.min() > 0.9999, (name, a, b)


def test_rest_pose_differences_cancel() -> None:
    # The puppet retargeted onto itself is itself, whatever rest pose the source had.
    rng = np.random.default_rng(1)
    rots = quat.normalize(quat.identity(5, PUPPET.num_joints) + 0.3 * rng.normal(size=(5, PUPPET.num_joints, 4)))
    from engine.clip import Clip

    clip = Clip("c", PUPPET, 30.0, np.tile([0.0, 0.95, 0.0], (5, 1)), rots)
    same = {n: n for n in PUPPET.names}
    back = retarget(clip, PUPPET, same, floor=False)
    assert quat.angle_between(back.rotations, clip.rotations).max() < 1e-6
    np.testing.assert_allclose(back.root, clip.root, atol=1e-9)


def test_other_rigs_walk_on_the_floor(mocap_dir: Path) -> None:
    for name in ("bandai1_walk_normal_001.bvh", "cmu_02_01_walk_ccbase.bvh", "cmu_16_36_runjog_daz.bvh"):
        clip = retarget(_source(mocap_dir, name), PUPPET)
        wpos, feet = _feet(clip)
        assert np.isfinite(wpos).all()
        assert feet.min() > -0.05 and np.percentile(feet.min(axis=1), 50) < 0.06, name
        assert np.linalg.norm(clip.root[-1, [0, 2]] - clip.root[0, [0, 2]]) > 2.0, name


def test_guess_joint_map_picks_family(mocap_dir: Path) -> None:
    expect = {
        "cmu_16_15_walk_daz.bvh": "cmu_daz",
        "bandai1_walk_normal_001.bvh": "bandai",
        "cmu_02_05_punch_ccbase.bvh": "cc_base",
    }
    for name, family in expect.items():
        got, mapping, _ = guess_joint_map(read_bvh(mocap_dir / name).names)
        assert got == family and len(mapping) == 17
    mixamo = [
        f"mixamorig:{n}"
        for n in (
            "Hips",
            "Spine",
            "Spine1",
            "Spine2",
            "Neck",
            "Head",
            "LeftArm",
            "LeftForeArm",
            "LeftHand",
            "RightArm",
            "RightForeArm",
            "RightHand",
            "LeftUpLeg",
            "LeftLeg",
            "LeftFoot",
            "LeftToeBase",
            "RightUpLeg",
            "RightLeg",
            "RightFoot",
        )
    ]
    family, mapping, aims = guess_joint_map(mixamo)
    assert (
        family == "cmu_mixamo" and mapping["chest"] == "mixamorig:Spine2" and aims["l_foot"] == "mixamorig:LeftToeBase"
    )
    assert set(JOINT_MAPS["cmu_daz"]) == set(PUPPET.names)
    with pytest.raises(ValueError, match="no joint map fits"):
        guess_joint_map(["root", "a", "b"])
