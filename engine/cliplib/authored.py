"""The puppet's locomotion set from authored clips: built-in clips where the library has none.

:class:`AuthoredClips` is the world resource the launcher inserts when a game plays a
library (from the set-up, see :mod:`engine.cliplib.embed`); the puppet plugin
(:func:`engine.blend.puppet.install_puppet_locomotion`) then builds the ``"humanoid"``
set with :func:`authored_locomotion` instead of the built-in one: the blend space over
the merged clips and its lookup table *re-measured* from them (through the disk cache).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

from engine.blend.locomotion import LocomotionSet
from engine.blend.puppet import build_locomotion
from engine.clip import Clip
from engine.cliplib.cache import MeasureCache
from engine.cliplib.library import set_digest
from engine.cliplib.roles import check_set

__all__ = ["AuthoredClips", "merged_clips", "authored_locomotion"]


@dataclass
class AuthoredClips:
    """Resource: the library's clips by role, and where the lookup measurement may be cached (``None``: nowhere)."""

    SIM_STATE = False

    clips: dict[str, Clip] = field(default_factory=dict)
    cache_dir: Path | None = None


def merged_clips(authored: Mapping[str, Clip]) -> dict[str, Clip]:
    """The built-in clips with the authored ones in their roles (and new roles added)."""
    from engine.clips import default_clips

    clips = default_clips()
    clips.update(authored)
    check_set(clips)
    return clips


def authored_locomotion(
    resource: AuthoredClips, density: int = 31, dt: float = 1.0 / 60.0
) -> tuple[LocomotionSet, MeasureCache | None]:
    """The locomotion set over the merged clips; its table from the cache when the clips were measured before."""
    clips = merged_clips(resource.clips)
    cache = None
    if resource.cache_dir is not None:
        cache = MeasureCache(resource.cache_dir, f"{set_digest(clips)}:{density}:{dt!r}")
    return build_locomotion(clips, density, dt, memo=cache), cache
