"""Clip sampling, looping and root motion; the clip file round trip and its refusals."""

import zipfile

import numpy as np
import pytest

from engine import quat
from engine.clip import Clip
from engine.clipfile import ClipFileError, load_clip, save_clip
from engine.humanoid import humanoid_skeleton

UP = np.array([0.0, 1.0, 0.0])


def walking_clip(frames=30, fps=30.0, speed=1.5, turn=0.0):
    """A root that walks along +Z (and turns by ``turn`` rad per second) with a knee swinging."""
    sk = humanoid_skeleton()
    t = np.arange(frames) / fps
    heading = turn * t
    root = np.zeros((frames, 3))
    root[:, 2] = speed * t
    root[:, 1] = 0.95 + 0.02 * np.sin(2 * np.pi * t * fps / frames)
    rot = quat.identity(frames, sk.num_joints)
    rot[:, 0] = quat.from_axis_angle(UP, heading)
    rot[:, sk.index("l_lower_leg")] = quat.from_axis_angle([1, 0, 0], 0.5 + 0.4 * np.sin(2 * np.pi * t * fps / frames))
    return Clip("walk", sk, fps, root, rot, loop=True)


def test_sampling_interpolates_between_frames():
    clip = walking_clip()
    a, b = clip.sample(0.0), clip.sample(1 / 30)
    mid = clip.sample(0.5 / 30)
    np.testing.assert_allclose(mid.root, (a.root + b.root) / 2, atol=1e-12)
    np.testing.assert_allclose(mid.rotations, quat.slerp(a.rotations, b.rotations, 0.5), atol=1e-12)


def test_vector_sampling_matches_scalar():
    clip = walking_clip()
    ts = np.array([0.0, 0.13, 0.77])
    many = clip.sample(ts)
    for k, t in enumerate(ts):
        np.testing.assert_allclose(many.rotations[k], clip.sample(t).rotations, atol=1e-12)


def test_loop_wraps_time_and_non_loop_clamps():
    clip = walking_clip()
    np.testing.assert_allclose(clip.sample(0.2).rotations, clip.sample(0.2 + clip.duration).rotations, atol=1e-12)
    one_shot = Clip("x", clip.skeleton, clip.fps, clip.root, clip.rotations, loop=False)
    np.testing.assert_allclose(one_shot.sample(99.0).root, clip.root[-1])
    np.testing.assert_allclose(one_shot.sample(-1.0).root, clip.root[0])


def test_root_motion_extraction_removes_travel_and_accumulates_over_loops():
    clip = walking_clip(speed=1.5).extract_root_motion()
    assert np.allclose(clip.root[:, [0, 2]], 0.0)
    assert np.allclose(clip.root[:, 1], walking_clip().root[:, 1])
    assert clip.average_speed() == pytest.approx(1.5, rel=1e-6)
    t1, _ = clip.sample_root_motion(0.5)
    t2, _ = clip.sample_root_motion(0.5 + 2 * clip.duration)
    np.testing.assert_allclose(t2 - t1, [0, 0, 2 * 1.5 * clip.duration], atol=1e-9)
    # Root motion is continuous across the loop seam.
    eps = 1e-4
    before, _ = clip.sample_root_motion(clip.duration - eps)
    after, _ = clip.sample_root_motion(clip.duration + eps)
    assert np.linalg.norm(after - before) < 1.5 * 3 * eps


def test_a_30_fps_loop_resampled_to_60_keeps_walking_across_its_seam():
    """A loop's last new frames move on towards the next cycle, not back to where it started."""
    clip = walking_clip(frames=30, fps=30.0, speed=1.5)
    np.testing.assert_allclose(clip.root_travel(), [0.0, 0.0, 1.5], atol=1e-4)  # the bob's closing step: 2nd order
    out = clip.resampled(60.0)
    assert out.loop and out.num_frames == 60 and out.duration == pytest.approx(clip.duration)
    np.testing.assert_allclose(np.diff(out.root[:, 2]), 1.5 / 60.0, atol=1e-12)  # no step back before the seam
    np.testing.assert_allclose(out.root_travel(), clip.root_travel(), atol=1e-4)
    # Played as it is, the sampling path still wraps (what play and the shipped recordings use).
    np.testing.assert_allclose(clip.sample(clip.duration - 0.5 / clip.fps).root, 0.5 * (clip.root[-1] + clip.root[0]))


def test_an_in_place_loop_gets_no_travel():
    clip = walking_clip(speed=0.0)
    np.testing.assert_allclose(clip.root_travel(), 0.0, atol=1e-4)
    assert not walking_clip().extract_root_motion().root_travel().any()


def test_root_motion_heading():
    clip = walking_clip(turn=0.5).extract_root_motion()
    _, h = clip.sample_root_motion(0.5)
    assert h == pytest.approx(0.25, abs=1e-6)
    assert np.allclose(quat.rotate(clip.rotations[:, 0], [0, 0, 1.0])[:, 0], 0.0, atol=1e-12)


def test_nan_clip_refused():
    clip = walking_clip()
    root = clip.root.copy()
    root[3, 1] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        Clip("bad", clip.skeleton, 30, root, clip.rotations)


def test_clip_file_round_trip(tmp_path):
    clip = walking_clip().extract_root_motion()
    clip = Clip(
        clip.name, clip.skeleton, clip.fps, clip.root, clip.rotations, True, clip.root_motion, {"left_down": 0.0}
    )
    path = save_clip(clip, tmp_path / "walk.ppclip")
    back = load_clip(path)
    assert back.name == "walk" and back.loop and back.markers == {"left_down": 0.0}
    np.testing.assert_array_equal(back.rotations, clip.rotations)
    np.testing.assert_array_equal(back.root_motion.translation, clip.root_motion.translation)
    assert back.skeleton.names == clip.skeleton.names
    assert not list(tmp_path.glob(".*tmp"))  # no temporary left behind


def test_truncated_clip_file_refused(tmp_path):
    path = save_clip(walking_clip(), tmp_path / "walk.ppclip")
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])
    with pytest.raises(ClipFileError, match="walk.ppclip"):
        load_clip(path)


def test_garbage_file_refused(tmp_path):
    path = tmp_path / "x.ppclip"
    path.write_bytes(b"not a clip at all")
    with pytest.raises(ClipFileError):
        load_clip(path)


def _rewrite_header(path, change):
    import json

    with np.load(path) as data:
        arrays = {k: data[k] for k in data.files}
    header = json.loads(arrays.pop("header").tobytes())
    change(header, arrays)
    with open(path, "wb") as f:  # a file object: np.savez would append ".npz" to the name
        np.savez(f, header=np.frombuffer(json.dumps(header).encode(), dtype=np.uint8), **arrays)


def test_wrong_version_refused(tmp_path):
    path = save_clip(walking_clip(), tmp_path / "walk.ppclip")
    _rewrite_header(path, lambda h, a: h.update(version=99))
    with pytest.raises(ClipFileError, match="version 99"):
        load_clip(path)


def test_altered_data_fails_checksum(tmp_path):
    path = save_clip(walking_clip(), tmp_path / "walk.ppclip")

    def alter(h, a):
        a["root"] = a["root"] + 1.0

    _rewrite_header(path, alter)
    with pytest.raises(ClipFileError, match="checksum"):
        load_clip(path)
    assert zipfile.is_zipfile(path)


def _rewrite_signed(path, change):
    """Like _rewrite_header, and the checksum made to match: what a hostile file can do."""
    from engine.clipfile import _digest

    def both(h, a):
        change(h, a)
        h["sha256"] = _digest(a)

    _rewrite_header(path, both)


@pytest.mark.parametrize(
    "change,says",
    [
        (lambda h, a: h.update(fps=float("nan")), "fps"),
        (lambda h, a: h.update(fps=float("inf")), "fps"),
        (lambda h, a: h.update(fps=-30), "fps"),
        (lambda h, a: h.update(markers=[1, 2]), "markers"),
        (lambda h, a: h.update(joints="Hips"), "joints"),
        (lambda h, a: h.update(loop="yes"), "loop"),
        (lambda h, a: a.update(offsets=np.full_like(a["offsets"], np.nan)), "offsets"),
        (lambda h, a: a.update(radii=-a["radii"] - 0.1), "radii"),
        (lambda h, a: a.update(root=a["root"] * 1e300), "root"),
        (lambda h, a: a.update(rotations=a["rotations"] * 2.0), "unit"),
        (lambda h, a: a.update(parents=a["parents"].astype(float)), "parents"),
        (lambda h, a: a.update(rotations=a["rotations"][:, :2]), "inconsistent"),
    ],
)
def test_absurd_values_with_a_matching_checksum_are_refused(tmp_path, change, says):
    path = save_clip(walking_clip(), tmp_path / "walk.ppclip")
    _rewrite_signed(path, change)
    with pytest.raises(ClipFileError, match=says):
        load_clip(path)


def test_deeply_nested_header_is_a_clip_error(tmp_path):
    path = tmp_path / "deep.ppclip"
    with open(path, "wb") as f:
        np.savez(f, header=np.frombuffer(b"[" * 100_000 + b"]" * 100_000, dtype=np.uint8))
    with pytest.raises(ClipFileError, match="corrupt"):
        load_clip(path)


def test_a_member_claiming_a_huge_array_is_refused_before_allocation(tmp_path):
    import io

    buf = io.BytesIO()
    np.lib.format.write_array_header_1_0(buf, {"descr": "<f8", "fortran_order": False, "shape": (10**11, 3)})
    path = tmp_path / "huge.ppclip"
    with zipfile.ZipFile(path, "w") as z:
        z.writestr("root.npy", buf.getvalue() + bytes(64))
    with pytest.raises(ClipFileError, match="claims"):
        load_clip(path)


def test_flipped_bytes_give_a_clip_error_and_nothing_else(tmp_path):
    good = save_clip(walking_clip(), tmp_path / "walk.ppclip").read_bytes()
    path = tmp_path / "bad.ppclip"
    rng = np.random.default_rng(5)
    for pos in rng.integers(0, len(good), 300):
        path.write_bytes(good[:pos] + bytes([good[pos] ^ 0x5A]) + good[pos + 1 :])
        try:
            load_clip(path)
        except ClipFileError:
            pass


def test_a_pipe_or_a_folder_is_refused(tmp_path):
    import os

    fifo = tmp_path / "clip.ppclip"
    os.mkfifo(fifo)
    for p in (fifo, tmp_path):
        with pytest.raises(ClipFileError, match="regular file"):
            load_clip(p)


def test_version_2_channels_round_trip_and_version_1_still_reads(tmp_path):
    from dataclasses import replace

    from engine.clipfile import VERSION, _digest
    from engine.fk import forward_kinematics

    assert VERSION == 2
    clip = walking_clip()
    f, j = clip.num_frames, clip.skeleton.num_joints
    grow = 1.0 + 0.1 * np.sin(np.linspace(0, 2 * np.pi, f))[:, None, None]
    chan = replace(clip, translations=clip.offsets() * grow, scales=np.tile(np.linspace(0.9, 1.1, j), (f, 1)))
    back = load_clip(save_clip(chan, tmp_path / "chan.ppclip"))
    assert np.array_equal(back.translations, chan.translations) and np.array_equal(back.scales, chan.scales)
    pos = forward_kinematics(back.skeleton, back.root, back.rotations, back.translations, back.scales)[0]
    rigid = forward_kinematics(clip.skeleton, clip.root, clip.rotations)[0]
    assert np.abs(pos - rigid).max() > 0.01  # the channels do move the joints
    # A file written before the channels existed (version 1, no channel arrays) reads as before.
    path = save_clip(clip, tmp_path / "old.ppclip")
    _rewrite_header(path, lambda h, a: h.update(version=1, sha256=_digest(a)))
    old = load_clip(path)
    assert old.translations is None and old.scales is None and np.array_equal(old.root, clip.root)
    # A bad channel is refused in one line.
    path = save_clip(chan, tmp_path / "bad.ppclip")

    def negative(h, a):
        a["scales"] = -a["scales"]
        h["sha256"] = _digest(a)

    _rewrite_header(path, negative)
    with pytest.raises(ClipFileError, match="scales must be positive"):
        load_clip(path)
