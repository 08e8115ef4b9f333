"""The clip library's character: added like a clip, kept beside the clips, checked like them, played by ``play``."""

from __future__ import annotations

from pathlib import Path

import pytest

from engine.character.setup import decode
from engine.cliplib.character import CHARACTER_FILE, library_character, remove_character, set_character
from engine.cliplib.library import ClipLibrary, ClipLibraryError
from input.recording import read_recording
from puppetphone.cli import main


def test_the_character_is_kept_checked_and_removed(mocap_dir: Path, tmp_path: Path) -> None:
    """Broken by writing the manifest without the kept entry (a clip add then drops the character): fails."""
    library = ClipLibrary(tmp_path / "lib")
    assert library_character(library) is None
    set_character(library, mocap_dir / "CesiumMan.glb")
    from engine.clips import default_clips
    from engine.humanoid import humanoid_skeleton

    library.add(default_clips()["walk"], "walk", humanoid_skeleton(), default_clips())  # a clip added after it
    value = library_character(library)
    assert value is not None and decode(value).name == "CesiumMan"
    assert set(library.load()) == {"walk"}
    (library.root / CHARACTER_FILE).write_bytes(b"glTF" + b"\0" * 40)
    with pytest.raises(ClipLibraryError, match="changed since it was added"):
        library_character(library)
    assert remove_character(library) and library_character(library) is None
    assert not (library.root / CHARACTER_FILE).exists() and set(library.load()) == {"walk"}


def test_a_refused_character_leaves_the_library_as_it_was(mocap_dir: Path, tmp_path: Path) -> None:
    from engine.character.load import CharacterError

    library = ClipLibrary(tmp_path / "lib")
    with pytest.raises(CharacterError):
        set_character(library, mocap_dir / "Fox.glb")
    assert library_character(library) is None and not (library.root / CHARACTER_FILE).exists()


def test_play_plays_the_librarys_character_and_records_it(mocap_dir: Path, tmp_path: Path) -> None:
    """``clips add X.glb --role character`` then ``play --clips DIR``: the recording carries the character
    and replays after the library is gone. Broken by not reading the library's character in play: the
    header has none."""
    lib = tmp_path / "lib"
    assert main(["clips", "add", str(mocap_dir / "CesiumMan.glb"), "--role", "character", "--clips", str(lib)]) == 0
    rec = tmp_path / "s.rec"
    assert main(["play", "sandbox", "--clips", str(lib), "--headless", "--frames", "30", "--record", str(rec)]) == 0
    assert read_recording(rec).header.setup["character"]["name"] == "CesiumMan"
    assert main(["clips", "remove", "character", "--clips", str(lib)]) == 0
    assert main(["replay", str(rec), "--verify", "--headless"]) == 0
