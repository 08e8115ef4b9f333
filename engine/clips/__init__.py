"""The default puppet's clips: idle, walk, run, crouch idle, crouch walk, get-up, mid-jump.

These are the seven clips of the thesis prototype (§6.3), authored here as keyframed
*intent* (where feet plant, how the pelvis bobs and sways, how arms swing) and solved
with an analytic leg IK at build time, so stance feet stay exactly where they were
planted. Locomotion cycles carry their travel as root motion and the sync-group markers
``{"left_down": 0.0, "right_down": 0.5}`` (left heel strike at phase 0).

Root conventions: ``root_motion`` is the smooth travel along +Z with zero heading (get-up
has its forward rise too); the clip's ``root`` keeps the pelvis's height *and* its small
sideways sway around that path, and the pelvis rotation keeps its walking yaw. Putting the
sway and yaw into root motion (what ``Clip.extract_root_motion`` on the raw pelvis would
do) would make the character's facing wobble every step and a loop drift sideways.
Clips are sampled at 60 fps.

Usage::

    from engine.clips import default_clips, foot_contacts
    walk = default_clips()["walk"]
    contacts = foot_contacts(walk)   # [F,2] bool, left/right
"""

from __future__ import annotations

from collections.abc import Mapping
from functools import lru_cache
from types import MappingProxyType

from engine.clip import Clip
from engine.clips.contacts import foot_contacts, foot_sliding, sole_points, world_poses
from engine.humanoid import humanoid_skeleton

__all__ = [
    "CLIP_NAMES",
    "LOCOMOTION",
    "build_default_clips",
    "default_clips",
    "foot_contacts",
    "foot_sliding",
    "sole_points",
    "world_poses",
]

CLIP_NAMES: tuple[str, ...] = ("idle", "walk", "run", "crouch_idle", "crouch_walk", "get_up", "mid_jump")
"""Keys of :func:`default_clips`, in the order the thesis lists them."""

LOCOMOTION: tuple[str, ...] = ("walk", "run", "crouch_walk")
"""The cyclic clips that travel and carry the left/right heel-strike markers."""


@lru_cache(maxsize=1)
def _build() -> Mapping[str, Clip]:
    from engine.clips.stored import cached_clips

    return MappingProxyType(cached_clips(build_default_clips)[0])


def build_default_clips() -> dict[str, Clip]:
    """The seven clips solved from their authored intent now (what :func:`default_clips` keeps on disk)."""
    from engine.clips._library import build_all

    built = build_all(humanoid_skeleton())
    return {name: built[name][0] for name in CLIP_NAMES}


def default_clips() -> dict[str, Clip]:
    """The seven default clips of the humanoid puppet, keyed by :data:`CLIP_NAMES`.

    Built once per machine and code version (about 1.5 s of CPU) and kept in the user cache
    (:mod:`engine.clips.stored`), then once per process in memory; the clips are immutable,
    and each call returns a fresh dict so a caller adding its own clips changes nobody else's.
    """
    return dict(_build())
