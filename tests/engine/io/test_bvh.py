"""BVH reading, writing and the quirks of real files (tests/engine/io mirrors engine/io)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from engine import quat
from engine.fk import forward_kinematics
from engine.io.bvh import BvhError, parse_bvh, read_bvh, write_bvh
from engine.io.bvh_convert import clip_to_bvh, detect_tpose_frames, skip_leading_tpose

SMALL = """HIERARCHY
ROOT hips
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Yrotation Xrotation Zrotation
  JOINT spine
  {
    OFFSET 0 10 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    End Site
    {
      OFFSET 0 5 0
    }
  }
  JOINT leg
  {
    OFFSET 3 0 0
    CHANNELS 6 Xposition Yposition Zposition Xrotation Zrotation Yrotation
    End Site
    {
      OFFSET 0 -40 0
    }
  }
}
MOTION
Frames: 3
Frame Time: 0.5
1 90 2 10 20 30 0 0 90 3 0 0 0 90 0
1 90 3 -170 20 30 0 0 0 3 0 0 45 0 0
1 90 4 190 20 30 0 0 0 3 0 0 0 0 0
"""


def _bvh_files(mocap_dir: Path) -> list[Path]:
    files = sorted(mocap_dir.glob("*.bvh"))
    assert files, "the mocap folder holds BVH files"
    return files


def test_parse_small_keeps_raw_structure() -> None:
    m = parse_bvh(SMALL, "small.bvh")
    assert m.names == ("hips", "spine", "leg")
    assert m.parents.tolist() == [-1, 0, 0]
    assert m.channels[0] == ("Xposition", "Yposition", "Zposition", "Yrotation", "Xrotation", "Zrotation")
    assert m.frame_time == 0.5 and m.fps == 2.0
    assert m.data.shape == (3, 15)
    np.testing.assert_array_equal(m.end_sites[2], [0, -40, 0])
    np.testing.assert_array_equal(m.column("spine", "zrotation"), [0, 0, 0])


def test_to_clip_orders_positions_and_tips() -> None:
    m = parse_bvh(SMALL, "small.bvh")
    clip = m.to_clip(scale=0.01, positions="replace")
    sk = clip.skeleton
    np.testing.assert_allclose(clip.root[:, 2], [0.02, 0.03, 0.04])
    # the root's own order is YXZ: R = Ry(10) Rx(20) Rz(30)
    expect = quat.mul(
        quat.mul(quat.from_axis_angle([0, 1, 0], np.radians(10)), quat.from_axis_angle([1, 0, 0], np.radians(20))),
        quat.from_axis_angle([0, 0, 1], np.radians(30)),
    )
    assert quat.angle_between(clip.rotations[0, 0], expect) < 1e-9
    # the leg's position channels (3,0,0) replace its OFFSET (3,0,0) instead of doubling it
    np.testing.assert_allclose(sk.offsets[2], [0.03, 0.0, 0.0])
    np.testing.assert_allclose(sk.tips[1], [0, 0.05, 0])
    np.testing.assert_allclose(sk.tips[2], [0, -0.40, 0])
    # -170° and 190° about Y are the same rotation as each other (Euler wrap)
    m2 = parse_bvh(SMALL.replace("1 90 4 190", "1 90 4 -170"), "s.bvh")
    c2 = m2.to_clip(scale=0.01)
    assert quat.angle_between(clip.rotations[2, 0], c2.rotations[2, 0]) < 1e-9


def test_round_trip_every_file(mocap_dir: Path, tmp_path: Path) -> None:
    for f in _bvh_files(mocap_dir):
        m = read_bvh(f)
        out = write_bvh(tmp_path / f.name, m)
        back = read_bvh(out)
        assert back.names == m.names and back.channels == m.channels, f.name
        assert back.parents.tolist() == m.parents.tolist()
        np.testing.assert_array_equal(back.offsets, m.offsets)
        np.testing.assert_array_equal(back.data, m.data)
        assert back.frame_time == m.frame_time
        assert back.end_sites.keys() == m.end_sites.keys()


def test_readme_counts(mocap_dir: Path) -> None:
    expect = {
        "cmu_16_15_walk_daz.bvh": (120, 472, 43, 132),
        "cmu_02_01_walk_ccbase.bvh": (60, 171, 101, 306),
        "bandai1_walk_normal_001.bvh": (30, 195, 22, 132),
        "cmu_02_05_punch_ccbase.bvh": (60, 927, 100, 303),
        "cmu_60_04_salsa_daz_scaled.bvh": (120, 1871, 43, 132),
    }
    for name, (fps, frames, joints, chans) in expect.items():
        m = read_bvh(mocap_dir / name)
        assert round(m.fps) == fps and m.num_frames == frames and m.num_joints == joints and m.data.shape[1] == chans


def _head_height_cm(path: Path, frame: int = 10) -> float:
    clip = read_bvh(path).to_clip(scale=1.0)
    wpos, _ = forward_kinematics(clip.skeleton, clip.root, clip.rotations)
    head = [i for i, n in enumerate(clip.skeleton.names) if n.lower() in ("head", "cc_base_head")][0]
    return float(wpos[frame, head, 1])


def test_position_channels_do_not_double_offsets(mocap_dir: Path) -> None:
    # README: head-joint height at frame 10 is about 135 file units in the Bandai clips.
    for name in ("bandai1_walk_normal_001.bvh", "bandai1_run_happy_001.bvh", "bandai1_punch_normal_001.bvh"):
        assert _head_height_cm(mocap_dir / name) == pytest.approx(135.0, rel=0.04), name
    # The iClone walk: ≈ 162-167 cm.
    assert 160.0 < _head_height_cm(mocap_dir / "cmu_02_01_walk_ccbase.bvh") < 170.0


def test_additive_root_positions_keep_feet_on_floor(mocap_dir: Path) -> None:
    # cmu_02_05's root channels are small deltas from its 105 cm OFFSET; "auto" adds them.
    clip = read_bvh(mocap_dir / "cmu_02_05_punch_ccbase.bvh").to_clip(scale=1.0)
    wpos, _ = forward_kinematics(clip.skeleton, clip.root, clip.rotations)
    foot = clip.skeleton.index("CC_Base_L_Foot")
    assert 0.0 < wpos[:, foot, 1].min() < 20.0
    replaced = read_bvh(mocap_dir / "cmu_02_05_punch_ccbase.bvh").to_clip(scale=1.0, positions="replace")
    wrong, _ = forward_kinematics(replaced.skeleton, replaced.root, replaced.rotations)
    assert wrong[:, foot, 1].min() < -50.0


def test_units_are_detected(mocap_dir: Path) -> None:
    daz = read_bvh(mocap_dir / "cmu_16_15_walk_daz.bvh").to_clip()
    for name, unit in (
        ("cmu_16_15_walk_daz.bvh", 0.01),
        ("bandai1_walk_normal_001.bvh", 0.01),
        ("cmu_60_04_salsa_daz_scaled.bvh", None),
    ):
        m = read_bvh(mocap_dir / name)
        auto = m.to_clip()
        raw = m.to_clip(scale=1.0)
        if unit is None:  # rescaled by its uploader to a 1.1 m figure in metres: no unit fits, scaled continuously
            unit = float(
                np.linalg.norm(daz.skeleton.offsets[1:], axis=1).sum()
                / np.linalg.norm(raw.skeleton.offsets[1:], axis=1).sum()
            )
            np.testing.assert_allclose(auto.skeleton.offsets, raw.skeleton.offsets * unit, rtol=0.02)
            continue
        np.testing.assert_allclose(auto.skeleton.offsets, raw.skeleton.offsets * unit)


def test_bandai_static_root_is_folded_into_hips(mocap_dir: Path) -> None:
    clip = read_bvh(mocap_dir / "bandai1_walk_normal_001.bvh").to_clip()
    assert clip.skeleton.names[0] == "Hips" and clip.skeleton.num_joints == 21
    assert np.linalg.norm(clip.root[-1] - clip.root[0]) > 3.0  # the walk travels metres


def test_tpose_lead_in(mocap_dir: Path) -> None:
    for name in ("cmu_16_15_walk_daz.bvh", "cmu_16_36_runjog_daz.bvh", "cmu_13_32_forward_jump_NEGATIVE_daz.bvh"):
        assert detect_tpose_frames(read_bvh(mocap_dir / name)) == 5, name
    assert detect_tpose_frames(read_bvh(mocap_dir / "cmu_60_04_salsa_daz_scaled.bvh")) in (5, 6)
    for name in ("bandai1_walk_normal_001.bvh", "cmu_02_01_walk_ccbase.bvh", "cmu_02_05_punch_ccbase.bvh"):
        assert detect_tpose_frames(read_bvh(mocap_dir / name)) == 0, name
    m = read_bvh(mocap_dir / "cmu_16_15_walk_daz.bvh")
    skipped = skip_leading_tpose(m)
    assert skipped.num_frames == m.num_frames - 5
    np.testing.assert_array_equal(skipped.data[0], m.data[5])


def test_unwrapped_removes_jumps(mocap_dir: Path) -> None:
    m = read_bvh(mocap_dir / "bandai1_run_happy_001.bvh")
    rot = m.rotation_columns()
    assert np.abs(np.diff(m.data[:, rot], axis=0)).max() > 300.0  # README: ≈355° single-frame jumps
    assert np.abs(np.diff(m.unwrapped().data[:, rot], axis=0)).max() < 180.0


def test_clip_export_round_trip(mocap_dir: Path, tmp_path: Path) -> None:
    clip = read_bvh(mocap_dir / "cmu_16_15_walk_daz.bvh").to_clip(skip_frames=5)
    for order in ("ZXY", "XYZ", "YZX"):
        path = write_bvh(tmp_path / f"walk_{order}.bvh", clip_to_bvh(clip, order=order))
        back = read_bvh(path).to_clip()
        assert back.skeleton.names == clip.skeleton.names
        np.testing.assert_allclose(back.skeleton.offsets, clip.skeleton.offsets, atol=1e-9)
        np.testing.assert_allclose(back.skeleton.tips, clip.skeleton.tips, atol=1e-9)
        np.testing.assert_allclose(back.root, clip.root, atol=1e-9)
        assert quat.angle_between(back.rotations, clip.rotations).max() < 1e-6
        assert back.fps == pytest.approx(clip.fps)


@pytest.mark.parametrize(
    ("text", "needle"),
    [
        ("HIERARCHY\nROOT a\n{\n  OFFSET 0 0\n}\n", ":4: OFFSET needs 3 numbers"),
        ("HIERARCHY\nROOT a\n{\n  OFFSET 0 0 0\n  CHANNELS 3 Xrotation Yrotation\n}\n", ":5: CHANNELS says 3"),
        ("HIERARCHY\nROOT a\n{\n  OFFSET 0 0 0\n  CHANNELS 1 Wrotation\n}\n", ":5: bad channel list"),
        ("HIERARCHY\nROOT a\n{\n  OFFSET 0 0 0\n", "unclosed braces"),
        ("hello\n", ":1: not a BVH file"),
        ("HIERARCHY\nROOT a\n{\n  OFFSET 0 0 0\n  CHANNELS 1 Xrotation\n}\n", "no MOTION section"),
        (
            "HIERARCHY\nROOT a\n{\n  OFFSET 0 0 0\n  CHANNELS 1 Xrotation\n}\nMOTION\nFrames: 2\nFrame Time: 0.1\n1\nx\n",
            ":11: frame 1 holds a non-number; 1 frames are complete",
        ),
    ],
)
def test_malformed_files_name_file_and_line(text: str, needle: str) -> None:
    with pytest.raises(BvhError, match="bad.bvh") as err:
        parse_bvh(text, "bad.bvh")
    assert needle in str(err.value)


def test_truncated_motion_says_how_many_frames(mocap_dir: Path, tmp_path: Path) -> None:
    text = (mocap_dir / "cmu_16_15_walk_daz.bvh").read_text()
    cut = tmp_path / "cut.bvh"
    cut.write_text(text[: len(text) - 5000])
    with pytest.raises(BvhError) as err:
        read_bvh(cut)
    msg = str(err.value)
    assert "cut.bvh" in msg and "of 472 frames are complete" in msg
    complete = int(msg.split("only ")[1].split(" of")[0])
    assert 400 < complete < 472


def test_write_is_atomic_and_refuses_bad_order(tmp_path: Path) -> None:
    m = parse_bvh(SMALL, "small.bvh")
    target = tmp_path / "keep.bvh"
    target.write_text("old")
    bad = type(m)(m.names, np.array([-1, 0, 5]), m.offsets, m.end_sites, m.channels, m.frame_time, m.data)
    with pytest.raises(BvhError):
        write_bvh(target, bad)
    assert target.read_text() == "old"
    assert list(tmp_path.iterdir()) == [target]


def _chain_bvh(depth: int, offset: str = "0 1 0", frame: str = "0 0 0 0 0 0", frame_time: str = "0.0083333") -> str:
    lines = [
        "HIERARCHY",
        "ROOT j0",
        "{",
        "  OFFSET 0 0 0",
        "  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation",
    ]
    for j in range(1, depth):
        lines += [f"JOINT j{j}", "{", f"  OFFSET {offset}", "  CHANNELS 0"]
    lines += ["}"] * depth
    return "\n".join(lines + ["MOTION", "Frames: 1", f"Frame Time: {frame_time}", frame]) + "\n"


def test_a_hierarchy_deeper_than_the_python_stack_reads_and_writes(tmp_path):
    from engine.io.bvh import MAX_JOINTS, format_bvh

    motion = parse_bvh(_chain_bvh(MAX_JOINTS))
    assert motion.num_joints == MAX_JOINTS
    path = write_bvh(tmp_path / "deep.bvh", motion)  # was a RecursionError
    back = read_bvh(path)
    assert back.names == motion.names and np.array_equal(back.parents, motion.parents)
    assert format_bvh(back) == format_bvh(motion)
    with pytest.raises(BvhError, match="more than"):
        parse_bvh(_chain_bvh(MAX_JOINTS + 1))


@pytest.mark.parametrize(
    "kw,says",
    [
        ({"offset": "0 nan 0"}, "OFFSET"),
        ({"offset": "0 1e308 0"}, "OFFSET"),
        ({"frame": "0 inf 0 0 0 0"}, "frame 0"),
        ({"frame": "0 0 0 0 5e307 0"}, "frame 0"),
        ({"frame_time": "inf"}, "frame time"),
        ({"frame_time": "nan"}, "frame time"),
    ],
)
def test_nan_and_absurd_numbers_are_a_bvh_error(kw, says):
    with pytest.raises(BvhError, match=says):
        parse_bvh(_chain_bvh(3, **kw))


def test_a_device_is_not_read(tmp_path):
    with pytest.raises(BvhError, match="regular file"):
        read_bvh("/dev/zero")
