"""Any motion file as a clip on the puppet's skeleton: ``.ppclip``, ``.bvh`` or glTF, retargeted.

What ``clips add`` and ``cycle --retarget puppet`` read. Motion files go through the one
loader, :func:`engine.io.motion_file.load_motion` (units judged by the figure, the glTF
animation chosen, a ``Frames:`` count that is off tolerated), and a clip on another
skeleton through :func:`engine.io.motion_file.to_puppet` (the name maps of
:mod:`engine.io.joint_maps`, or the user's ``--joint-map``): bone directions copied, the
root's travel scaled by the ratio of leg lengths so the stride fits the puppet's legs,
and the motion shifted so the feet stand on y = 0.
"""

from __future__ import annotations

from pathlib import Path

from engine.clip import Clip
from engine.io.formats import motion_format, suffixes
from engine.skeleton import Skeleton

__all__ = ["SOURCE_SUFFIXES", "read_motion", "read_source", "to_puppet"]

SOURCE_SUFFIXES = suffixes(skeletal=True, readable=True)
"""What ``clips add`` reads: every clip format of :data:`engine.io.formats.FORMATS`."""


def read_motion(
    path: str | Path,
    animation: int | str | None = None,
    units: str | None = None,
    joint_map: dict[str, str] | None = None,
    up: str | None = None,
    height: float | None = None,
) -> Clip:
    """The clip in ``path`` (a glTF's chosen animation; a CMU BVH without its T-pose lead-in).

    A file that already is a loop (``cycle -o loop.bvh`` closes its loop with the first
    pose) is read as that loop, as the same loop written as ``.glb`` or ``.ppclip`` is.

    Raises:
        ValueError: not a motion file this build reads, or a damaged one (the message says which).
        OSError: the file cannot be opened.
    """
    return read_source(path, animation, units, joint_map, up, height)[0]


def read_source(
    path: str | Path,
    animation: int | str | None = None,
    units: str | None = None,
    joint_map: dict[str, str] | None = None,
    up: str | None = None,
    height: float | None = None,
) -> tuple[Clip, str | None]:
    """:func:`read_motion`'s clip and the note to show the user about its size (``None``: read in a unit as a human).

    The note is :attr:`~engine.io.motion_file.MotionFile.unit_note`: a figure scaled to a
    stated size, or one judged by its extent because it has no legs.
    """
    path = Path(path)
    fmt = motion_format(path)
    if fmt is None or fmt.read is None:
        raise ValueError(
            f"{path.name}: unknown motion type {path.suffix.lower()!r}; use one of {', '.join(SOURCE_SUFFIXES)}"
        )
    motion = fmt.read(path, animation=animation, units=units, joint_map=joint_map, up=up, height=height)
    return motion.clip, motion.unit_note


def to_puppet(clip: Clip, skeleton: Skeleton, joint_map: dict[str, str] | None = None) -> tuple[Clip, str | None]:
    """``clip`` on ``skeleton`` (retargeted unless it already is on it) and the joint map used (``None``: none)."""
    if tuple(clip.skeleton.names) == tuple(skeleton.names):
        return clip, None
    from engine.io.motion_file import to_puppet as retarget_to_puppet

    return retarget_to_puppet(clip, joint_map)
