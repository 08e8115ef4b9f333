"""The clip library's character: the rigged ``.glb`` every ``play`` of the library's clips is played by.

``puppetphone clips add hero.glb --role character`` checks the file as ``play --character`` does
(:func:`engine.character.load.read_character`), copies it into the library folder as
``character.glb`` and names it in the manifest beside the clips::

    "character": {"file": "character.glb", "name": "hero", "sha256": "…", "joint_map": null}

A ``play`` of the library without ``--character`` then plays it: :func:`library_character` gives the
set-up value (the bytes travel in the recording, as the clips do), checked against the recorded
hash like every clip of the library. The file is written before the manifest names it, so an
interrupted add leaves the library as it was.
"""

from __future__ import annotations

import hashlib
from pathlib import Path
from typing import Any

from engine.atomic import atomic_write_bytes
from engine.character.load import Character, read_character
from engine.character.setup import encode
from engine.cliplib.library import ClipLibrary, ClipLibraryError
from engine.humanoid import JOINTS

__all__ = ["CHARACTER_ROLE", "CHARACTER_FILE", "set_character", "remove_character", "library_character"]

CHARACTER_ROLE = "character"
CHARACTER_FILE = "character.glb"


def set_character(library: ClipLibrary, path: str | Path, joint_map: dict[str, str] | None = None) -> Character:
    """Make the ``.glb`` at ``path`` the library's character (replacing any); ``CharacterError`` when refused."""
    character, data = read_character(path, joint_map)
    library.root.mkdir(parents=True, exist_ok=True)
    atomic_write_bytes(library.root / CHARACTER_FILE, data)
    entry = {
        "file": CHARACTER_FILE,
        "name": character.name,
        "sha256": hashlib.sha256(data).hexdigest(),
        "joint_map": dict(sorted(joint_map.items())) if joint_map else None,
    }
    library._write_manifest(library.entries(), character=entry)
    return character


def remove_character(library: ClipLibrary) -> bool:
    """Drop the library's character (the mannequin plays again); whether there was one."""
    if library.raw_manifest().get("character") is None:
        return False
    library._write_manifest(library.entries(), keep=False)
    (library.root / CHARACTER_FILE).unlink(missing_ok=True)
    return True


def library_character(library: ClipLibrary) -> dict[str, Any] | None:
    """The set-up value of the library's character, or ``None`` without one.

    Raises:
        ClipLibraryError: the entry is malformed or the file changed since it was added (one line).
    """
    entry = library.raw_manifest().get("character")
    if entry is None:
        return None
    where = library.manifest_path
    if not (
        isinstance(entry, dict)
        and entry.get("file") == CHARACTER_FILE
        and isinstance(entry.get("name"), str)
        and isinstance(entry.get("sha256"), str)
    ):
        raise ClipLibraryError(f"{where}: the character entry needs file {CHARACTER_FILE!r}, a name and a sha256")
    joint_map = entry.get("joint_map")
    if joint_map is not None and not (
        isinstance(joint_map, dict) and all(k in JOINTS and isinstance(v, str) for k, v in joint_map.items())
    ):
        raise ClipLibraryError(f"{where}: the character's joint map is not {{puppet role: file joint}}")
    try:
        data = (library.root / CHARACTER_FILE).read_bytes()
    except OSError as exc:
        raise ClipLibraryError(f"library {library.root}: cannot read its character: {exc.strerror}") from None
    if hashlib.sha256(data).hexdigest() != entry["sha256"]:
        raise ClipLibraryError(
            f"library {library.root}: {CHARACTER_FILE} changed since it was added; "
            f"add it again (puppetphone clips add FILE.glb --role character)"
        )
    return encode(data, entry["name"], joint_map)
