"""A character as a game set-up value: the ``.glb``'s bytes travel in the recording's header.

``play --character FILE`` reads the file *once*, in the launcher; its bytes (base64), their
SHA-256 and the joint map given with it go into the game's set-up, so ``Game.install`` builds
the character from the set-up alone and ``replay --verify`` rebuilds the very same puppet
after the file is moved, edited or deleted (as :mod:`engine.cliplib.embed` does for clips).
:func:`decode` is the validation boundary of that value: type, size, hash, then the file itself.
"""

from __future__ import annotations

import base64
import binascii
import hashlib
from typing import Any

from engine.character.load import MAX_CHARACTER, Character, CharacterError, character_from_bytes
from engine.humanoid import JOINTS

__all__ = ["encode", "decode", "character_setup"]


def encode(data: bytes, name: str, joint_map: dict[str, str] | None = None) -> dict[str, Any]:
    """The set-up value of a character file's ``data`` (and the ``--joint-map`` it was opened with)."""
    return {
        "name": name,
        "sha256": hashlib.sha256(data).hexdigest(),
        "glb": base64.b64encode(data).decode("ascii"),
        "joint_map": dict(sorted(joint_map.items())) if joint_map else None,
    }


def decode(value: Any) -> Character:
    """The character of an :func:`encode` value, checked.

    Raises:
        CharacterError: in one line: not the shape above, over :data:`MAX_CHARACTER`, a hash that
            does not match (the recording was altered), or a file the character reader refuses.
    """
    if not isinstance(value, dict) or not all(isinstance(value.get(k), str) for k in ("name", "sha256", "glb")):
        raise CharacterError("the recorded character is not {'name', 'sha256', 'glb', 'joint_map'}")
    if len(value["glb"]) > 4 * (MAX_CHARACTER // 3 + 1):
        raise CharacterError(f"the recorded character is over {MAX_CHARACTER >> 20} MB")
    joint_map = value.get("joint_map")
    if joint_map is not None and not (
        isinstance(joint_map, dict)
        and all(isinstance(k, str) and k in JOINTS and isinstance(v, str) for k, v in joint_map.items())
    ):
        raise CharacterError("the recorded character's joint map is not {puppet role: file joint}")
    try:
        data = base64.b64decode(value["glb"], validate=True)
    except (binascii.Error, ValueError):
        raise CharacterError("the recorded character is not base64") from None
    if hashlib.sha256(data).hexdigest() != value["sha256"]:
        raise CharacterError("the recorded character does not match its hash; the recording was altered")
    return character_from_bytes(data, value["name"][:80], joint_map)


def character_setup(path: str, joint_map_file: str | None = None) -> dict[str, Any]:
    """``play --character FILE [--joint-map MAP]``: the set-up value, the file checked as a replay will check it.

    Says once on stderr what of the file is not drawn (morph targets…).

    Raises:
        CharacterError: the file or the map refused, in one line.
    """
    import sys

    from engine.character.load import read_character
    from engine.io.motion_file import MotionFileError, load_joint_map

    try:
        joint_map = load_joint_map(joint_map_file) if joint_map_file else None
    except MotionFileError as exc:
        raise CharacterError(str(exc)) from None
    character, data = read_character(path, joint_map)
    if character.ignored:
        print(f"{character.name}: not drawn: {', '.join(character.ignored)}", file=sys.stderr)
    return encode(data, character.name, joint_map)
