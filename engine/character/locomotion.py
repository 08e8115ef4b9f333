"""A character's locomotion set: the puppet's clips retargeted to it and a lookup table measured for it.

The clips (built-in, or a library's authored ones over them) are carried onto the character's
skeleton by :func:`engine.io.retarget.retarget_proportions`; the blend space's lookup table is
then *measured* from those clips — a shorter character walks slower at the same blend — and
kept on disk like the built-in table, keyed by the character file's SHA-256 and the clips'
content hash (:class:`engine.cliplib.cache.MeasureCache`), so a second start skips the ~1.5 s
measurement. Within a process a set is built once per character and clip set.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from engine.blend.locomotion import LocomotionSet
from engine.blend.puppet import build_locomotion
from engine.character.load import Character
from engine.clip import Clip
from engine.cliplib.cache import MeasureCache, default_cache_dir
from engine.cliplib.library import set_digest
from engine.io.retarget import retarget_proportions

__all__ = ["character_clips", "character_locomotion"]

_BUILT: dict[tuple[str, str, int, float], LocomotionSet] = {}


def character_clips(character: Character, clips: Mapping[str, Clip]) -> dict[str, Clip]:
    """``clips`` (on the puppet's skeleton) played by ``character``."""
    return {name: retarget_proportions(clip, character.rig.skeleton) for name, clip in clips.items()}


def character_locomotion(
    character: Character,
    clips: Mapping[str, Clip],
    density: int = 31,
    dt: float = 1.0 / 60.0,
    cache_dir: Path | None = None,
) -> LocomotionSet:
    """The character's locomotion set over ``clips`` retargeted, its table from the disk cache when measured before.

    Args:
        clips: the puppet's clips by role (``default_clips()`` or the library's merged ones).
        cache_dir: where measured tables are kept (default: the user cache, as the built-in one's).
    """
    key = (character.digest, set_digest(clips), density, dt)
    if key not in _BUILT:
        own = character_clips(character, clips)
        cache = MeasureCache(
            cache_dir or default_cache_dir(), f"character:{character.digest}:{set_digest(own)}:{density}:{dt!r}"
        )
        _BUILT[key] = build_locomotion(own, density, dt, memo=cache)
    return _BUILT[key]
