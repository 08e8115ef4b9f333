"""Any motion file as a clip on the puppet's skeleton: ``.ppclip``, ``.bvh`` or glTF, retargeted.

What ``clips add`` and ``cycle --retarget puppet`` read. A clip on another skeleton is
retargeted with :func:`engine.io.retarget.retarget` (the name maps of
:mod:`engine.io.joint_maps` — CMU/DAZ, CC_Base, Bandai, Mixamo): bone directions copied,
the root's travel scaled by the ratio of leg lengths so the stride fits the puppet's
legs, and the motion shifted so the feet stand on y = 0.
"""

from __future__ import annotations

from pathlib import Path

from engine.clip import Clip
from engine.skeleton import Skeleton

__all__ = ["SOURCE_SUFFIXES", "read_motion", "to_puppet"]

SOURCE_SUFFIXES = (".ppclip", ".bvh", ".glb", ".gltf")


def read_motion(path: str | Path) -> Clip:
    """The clip in ``path`` (a glTF's first animation; a CMU BVH without its T-pose lead-in).

    Raises:
        ValueError: not a motion file this build reads, or a damaged one (the message says which).
        OSError: the file cannot be opened.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".ppclip":
        from engine.clipfile import load_clip

        return load_clip(path)
    if suffix == ".bvh":
        from engine.io.bvh import read_bvh
        from engine.io.bvh_convert import detect_tpose_frames

        motion = read_bvh(path)
        return motion.to_clip(skip_frames=detect_tpose_frames(motion))
    if suffix in (".glb", ".gltf"):
        from engine.io.gltf_clip import load_gltf_clips

        clips = load_gltf_clips(path)
        if not clips:
            raise ValueError(f"{path.name} has no animation")
        return clips[0]
    raise ValueError(f"{path.name}: unknown motion type {suffix!r}; use one of {', '.join(SOURCE_SUFFIXES)}")


def to_puppet(clip: Clip, skeleton: Skeleton) -> tuple[Clip, bool]:
    """``clip`` on ``skeleton`` (retargeted unless it already is on it) and whether it was retargeted."""
    if tuple(clip.skeleton.names) == tuple(skeleton.names):
        return clip, False
    from engine.io.retarget import retarget

    return retarget(clip, skeleton), True
