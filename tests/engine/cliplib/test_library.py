"""The library folder: add, load, remove; a damaged manifest or an altered clip refused in one line."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from engine.clipfile import save_clip
from engine.cliplib.library import ClipLibrary, ClipLibraryError, clip_digest, default_library_dir
from engine.cliplib.roles import conform
from engine.clips import default_clips
from engine.humanoid import humanoid_skeleton

SK = humanoid_skeleton()


def _slow_walk():  # type: ignore[no-untyped-def]
    """The built-in walk resampled to 50 fps and conformed: a different clip that fits the walk role."""
    return conform(default_clips()["walk"].resampled(50.0), "walk")


def test_default_folder_honours_xdg_data_home(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path))
    assert default_library_dir() == tmp_path / "puppetphone" / "clips"
    monkeypatch.delenv("XDG_DATA_HOME")
    assert default_library_dir() == Path.home() / ".local" / "share" / "puppetphone" / "clips"


def test_add_load_remove(tmp_path: Path) -> None:
    lib = ClipLibrary(tmp_path / "lib")
    assert lib.entries() == {} and lib.load() == {}  # a missing library is an empty one
    walk = _slow_walk()
    entry = lib.add(walk, "walk", SK, default_clips(), source="take.bvh")
    assert entry.file == "walk.ppclip" and entry.source == "take.bvh"
    loaded = lib.load()
    assert list(loaded) == ["walk"] and clip_digest(loaded["walk"]) == entry.sha256
    assert np.allclose(loaded["walk"].rotations, walk.rotations, atol=1e-15)
    manifest = json.loads((tmp_path / "lib" / "clips.json").read_text())
    assert manifest["format"] == "puppetphone-clips" and manifest["clips"]["walk"]["sha256"] == entry.sha256
    lib.remove("walk")
    assert lib.load() == {} and not (tmp_path / "lib" / "walk.ppclip").exists()
    with pytest.raises(ClipLibraryError, match="has no walk"):
        lib.remove("walk")


def test_a_clip_refused_for_its_role_leaves_the_library_as_it_was(tmp_path: Path) -> None:
    lib = ClipLibrary(tmp_path)
    lib.add(_slow_walk(), "walk", SK, default_clips())
    before = (tmp_path / "clips.json").read_bytes()
    with pytest.raises(ClipLibraryError, match="no forward speed"):
        lib.add(default_clips()["idle"], "walk", SK, default_clips())
    brisk = replace(default_clips()["walk"], fps=90.0)  # the walk played 1.5 times as fast: 1.95 m/s
    lib.add(conform(brisk, "walk"), "walk", SK, default_clips())
    before = (tmp_path / "clips.json").read_bytes()
    with pytest.raises(ClipLibraryError, match=r"the walk \(1.95 m/s\) must be slower than the run \(1.89 m/s\)"):
        lib.add(conform(replace(default_clips()["walk"], fps=87.0), "run"), "run", SK, default_clips())
    assert (tmp_path / "clips.json").read_bytes() == before and len(lib.load()) == 1


def test_a_clip_changed_behind_the_manifest_is_refused(tmp_path: Path) -> None:
    lib = ClipLibrary(tmp_path)
    lib.add(_slow_walk(), "walk", SK, default_clips())
    save_clip(default_clips()["walk"], tmp_path / "walk.ppclip")  # another valid clip in its place
    with pytest.raises(ClipLibraryError, match="changed since it was added as the walk"):
        lib.load()
    (tmp_path / "walk.ppclip").write_bytes(b"garbage")
    with pytest.raises(ClipLibraryError, match="walk: .*not a readable clip"):
        lib.load()
    (tmp_path / "walk.ppclip").unlink()
    with pytest.raises(ClipLibraryError, match="walk"):
        lib.load()


@pytest.mark.parametrize(
    ("text", "reason"),
    [
        ("{", "not valid JSON"),
        ("[]", "not a puppetphone-clips manifest"),
        ('{"format": "puppetphone-clips", "version": 9, "clips": {}}', "version 9"),
        (
            '{"format": "puppetphone-clips", "version": 1, "clips": {"walk": {"file": "../x.ppclip", "sha256": "0"}}}',
            "a library clip is a .ppclip in the folder",
        ),
        ('{"format": "puppetphone-clips", "version": 1, "clips": {"walk": {"file": 3}}}', "needs 'file'"),
    ],
)
def test_a_damaged_manifest_is_refused_in_one_line(tmp_path: Path, text: str, reason: str) -> None:
    (tmp_path / "clips.json").write_text(text)
    with pytest.raises(ClipLibraryError, match=reason) as info:
        ClipLibrary(tmp_path).entries()
    assert "\n" not in str(info.value)


@given(
    st.recursive(
        st.none() | st.booleans() | st.integers() | st.text(max_size=12),
        lambda c: st.lists(c, max_size=4) | st.dictionaries(st.text(max_size=8), c, max_size=4),
        max_leaves=20,
    )
)
def test_fuzz_manifest(tmp_path_factory: pytest.TempPathFactory, value: object) -> None:
    folder = tmp_path_factory.mktemp("fuzz")
    doc = {"format": "puppetphone-clips", "version": 1, "clips": value}
    (folder / "clips.json").write_text(json.dumps(doc))
    try:
        ClipLibrary(folder).load()
    except ClipLibraryError as exc:
        assert "\n" not in str(exc)


def test_a_clips_add_killed_after_writing_the_clip_leaves_the_library_loading(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The kill falls between the clip and the manifest: the old walk still loads, then the new one replaces it."""
    lib = ClipLibrary(tmp_path / "lib")
    first = lib.add(_slow_walk(), "walk", SK, default_clips())
    second_walk = default_clips()["walk"].resampled(55.0)

    def killed(self, entries):  # type: ignore[no-untyped-def]
        raise KeyboardInterrupt("killed before the manifest was written")

    with monkeypatch.context() as m:
        m.setattr(ClipLibrary, "_write_manifest", killed)
        with pytest.raises(KeyboardInterrupt):
            lib.add(second_walk, "walk", SK, default_clips())
    assert clip_digest(lib.load()["walk"]) == first.sha256  # nothing earlier was lost
    second = lib.add(second_walk, "walk", SK, default_clips())
    assert second.file != first.file and clip_digest(lib.load()["walk"]) == second.sha256
    assert sorted(p.name for p in (tmp_path / "lib").iterdir()) == sorted(["clips.json", second.file])
    assert lib.add(_slow_walk(), "walk", SK, default_clips()).file == first.file
