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


@pytest.mark.parametrize("edit,says", [
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
])
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
