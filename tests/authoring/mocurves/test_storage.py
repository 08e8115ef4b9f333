"""Save/load round trip (bit for bit), refusal of mismatched side files, exports."""

from __future__ import annotations

import json

import pytest

from authoring.mocurves import EditSession, SessionFileError, bake_root_motion, export_clip, load_session, save_session
from engine.io import read_bvh, read_gltf


def test_save_load_round_trip_is_exact(walk, tmp_path):
    s = EditSession(walk, tau=4, sigma=0.3)
    s.retime("l_foot", {20: 0.4})
    s.scale_arrow("l_foot", 20, 0.3)
    path = save_session(s, tmp_path / "walk_edit.ppclip")
    back = load_session(path)
    assert back.clip.root.tobytes() == s.clip.root.tobytes()
    assert back.clip.rotations.tobytes() == s.clip.rotations.tobytes()
    assert back.scales.tobytes() == s.scales.tobytes()
    assert back.clip.root_motion.translation.tobytes() == s.clip.root_motion.translation.tobytes()
    assert back.pins("l_foot") == {20} and back.tau == 4 and back.sigma == 0.3
    assert sorted(p.name for p in tmp_path.iterdir()) == ["walk_edit.mocurves.json", "walk_edit.ppclip"]


def test_mismatched_or_newer_side_file_is_refused(walk, tmp_path):
    s = EditSession(walk)
    path = save_session(s, tmp_path / "a.ppclip")
    side = tmp_path / "a.mocurves.json"
    data = json.loads(side.read_text())
    s.retime("hips", {3: 0.1})
    save_session(s, tmp_path / "b.ppclip")
    (tmp_path / "b.mocurves.json").write_text(json.dumps(data))  # a's side file beside b
    with pytest.raises(SessionFileError, match="another version"):
        load_session(tmp_path / "b.ppclip")
    data["version"] = 99
    side.write_text(json.dumps(data))
    with pytest.raises(SessionFileError, match="newer"):
        load_session(path)
    with pytest.raises(ValueError, match=".ppclip"):
        save_session(s, tmp_path / "c.bvh")


def test_exports_to_bvh_and_gltf_carry_the_travel(walk, tmp_path):
    baked = bake_root_motion(walk)
    assert baked.root_motion is None
    assert baked.root[-1, 2] - baked.root[0, 2] == pytest.approx(walk.root_motion.translation[-1, 2], abs=1e-9)
    bvh = read_bvh(export_clip(walk, tmp_path / "walk.bvh"))
    assert bvh.data.shape[0] == walk.num_frames + 1  # a loop is closed: its first pose again, a cycle on
    # Root Z position (cm) runs forward with the travel: the BVH walks, a whole cycle's travel to the closing frame.
    z = bvh.data[:, list(bvh.channels[0]).index("Zposition")]
    assert z[-2] - z[0] == pytest.approx(100 * walk.root_motion.translation[-1, 2], rel=1e-6)
    assert z[-1] - z[0] == pytest.approx(100 * walk.cycle_travel()[0][2], rel=1e-6)
    asset = read_gltf(export_clip(walk, tmp_path / "walk.glb"))
    assert len(asset.animations) == 1
    assert export_clip(walk, tmp_path / "w.ppclip").exists()
    with pytest.raises(ValueError, match="export to one of"):
        export_clip(walk, tmp_path / "walk.fbx")
    assert not (tmp_path / "walk.fbx").exists()


@pytest.mark.parametrize(
    "edit,says",
    [
        (lambda d: d.pop("scales"), "scales"),  # was a KeyError
        (lambda d: d.update(scales=d["scales"][:-1]), "scales"),
        (lambda d: d["scales"][0].__setitem__(0, float("inf")), "scales"),
        (lambda d: d["scales"][0].__setitem__(0, "big"), "scales"),
        (lambda d: d.update(pins={"l_foot": [10**9]}), "pins"),
        (lambda d: d.update(pins=[1, 2]), "pins"),
        (lambda d: d.update(tau=-3), "tau"),
        (lambda d: d.update(sigma=float("nan")), "sigma"),
        (lambda d: d.update(version="2"), "version"),
        (lambda d: d.clear(), "not a MoCurves"),
    ],
)
def test_a_damaged_side_file_is_a_session_file_error(walk, tmp_path, edit, says):
    path = save_session(EditSession(walk), tmp_path / "a.ppclip")
    side = tmp_path / "a.mocurves.json"
    data = json.loads(side.read_text())
    edit(data)
    side.write_text(json.dumps(data))
    with pytest.raises(SessionFileError, match=says):
        load_session(path)


def test_a_deeply_nested_side_file_is_a_session_file_error(walk, tmp_path):
    path = save_session(EditSession(walk), tmp_path / "a.ppclip")
    (tmp_path / "a.mocurves.json").write_text("[" * 100_000 + "]" * 100_000)
    with pytest.raises(SessionFileError, match="RecursionError"):
        load_session(path)


@pytest.mark.parametrize("name", ["idle", "walk", "run", "crouch_idle", "crouch_walk"])
def test_a_saved_session_reopens_unedited_and_again_after_a_second_save(name, tmp_path):
    """Loading renormalises rotations (last bit); the side file's checksum must be of the clip as loaded."""
    from engine.clips import default_clips

    path = save_session(EditSession(default_clips()[name]), tmp_path / f"{name}.ppclip")
    back = load_session(path)
    again = load_session(save_session(back, tmp_path / f"{name}_2.ppclip"))
    assert again.clip.num_frames == back.clip.num_frames and again.scales.tobytes() == back.scales.tobytes()


def _fill_leaving(folder, room: int) -> None:  # type: ignore[no-untyped-def]
    """Fill the disk under ``folder`` up to ``room`` free bytes."""
    import os

    fd = os.open(folder / ".more", os.O_WRONLY | os.O_CREAT, 0o600)
    try:
        while os.write(fd, b"\0" * 4096):
            pass
    except OSError:
        pass
    finally:
        os.close(fd)
    os.truncate(folder / ".more", max(0, (folder / ".more").stat().st_size - room))


@pytest.mark.parametrize("first", ["an edit", "the clip alone"])
def test_a_disk_full_between_the_side_file_and_the_clip_leaves_the_earlier_save_opening(walk, tmp_path, first):
    """A real full disk with room for the small side file and not for the clip: the side file is
    replaced, the clip is not. Broken on purpose: without ``previous`` in the side file the earlier
    save was refused ("belongs to another version ... move it away")."""
    from engine.atomic import WriteError
    from engine.clipfile import save_clip
    from tests.faults import full_disk

    with full_disk(tmp_path / "disk", free=200 << 10) as disk:
        path = disk / "walk_edit.ppclip"
        s = EditSession(walk, tau=3, sigma=0.2)
        if first == "an edit":
            s.scale_arrow("l_foot", 20, 0.3)
            save_session(s, path)
        else:  # a clip from `cycle`, no session file yet
            save_clip(walk, path)
        before = load_session(path)
        s.retime("hips", {3: 0.1})
        s.tau = 7
        _fill_leaving(disk, 20 << 10)  # the side file (~13 KB) fits, the clip (~26 KB) does not
        with pytest.raises(WriteError, match="space"):
            save_session(s, path)
        assert json.loads((disk / "walk_edit.mocurves.json").read_text())["tau"] == 7  # the side file did go
        back = load_session(path)  # and the clip still opens as it was saved
        assert back.clip.rotations.tobytes() == before.clip.rotations.tobytes()
        assert back.scales.tobytes() == before.scales.tobytes() and back.tau == before.tau
        (disk / ".more").unlink()
        save_session(s, path)  # room again: the new pair opens as the new save
        again = load_session(path)
        assert again.tau == 7 and again.clip.rotations.tobytes() == s.clip.rotations.tobytes()
