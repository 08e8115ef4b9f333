"""A motion file (BVH, glTF, GLB) opened as a loop for editing, on its own skeleton or the puppet's.

MoCurves edits cycles. A file that already is one (a game asset's walk, or a loop this
project exported: its last pose is its first) opens as that loop, the closing frame
dropped; any other take goes through the cycle extractor first, so the editor opens the
loop ``puppetphone cycle`` would write. With ``retarget`` the loop is moved onto the
puppet's skeleton (a built-in name map, or the user's ``--joint-map``). The travel is split
into root motion, so the loop plays in place like the built-in cycles.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from engine.clip import Clip

if TYPE_CHECKING:
    from authoring.cycles.take_range import Bound
    from engine.io.motion_file import MotionFile

__all__ = ["open_loop"]


def open_loop(
    path: str | Path,
    animation: int | str | None = None,
    units: str | None = None,
    joint_map: dict[str, str] | None = None,
    up: str | None = None,
    height: float | None = None,
    retarget: bool = False,
    start: Bound | None = None,
    end: Bound | None = None,
    items: list[str] | None = None,
) -> tuple[Clip, str]:
    """The loop of a motion file and a one-line note of how it was made.

    ``start``/``end`` (:class:`~authoring.cycles.take_range.Bound`) pick the part of a take
    the loop is extracted from, ``items`` the joints it is extracted from (the rest keep
    their mean pose); a take refused there names the part that loops instead.

    Raises ``ValueError`` (a :class:`~engine.io.motion_file.MotionFileError`, a
    :class:`~authoring.cycles.extract.CycleError` or a trajectory error) saying why not.
    """
    from authoring.cycles.extract import CycleError, extract_cycle
    from authoring.cycles.formats import loop_clip, performance_from_motion
    from authoring.cycles.take_range import refusal_hint
    from engine.io.motion_file import load_motion, load_motion_loop, to_puppet

    motion = load_motion_loop(path, animation=animation, units=units, joint_map=joint_map, up=up, height=height)
    clip = motion.clip
    if start is not None or end is not None:
        # The part is cut from the take as stored (a closed loop keeps its closing frame).
        motion = load_motion(
            path, animation=animation, units=units, joint_map=joint_map, up=up, height=height, skip_tpose=not clip.loop
        )
        loop, note = _loop_of_part(motion, start, end, items)
    elif clip.loop and not items:  # a loop our glTF writer marked as one, or a closed loop (its last pose is its first)
        loop, note = clip, f"{motion.source.name}: a {'seamless ' * motion.seamless}loop of {clip.num_frames} frames"
    else:
        perf = performance_from_motion(motion, items)
        try:
            result = extract_cycle(perf.trajectory, np.random.default_rng(0))
        except CycleError as exc:  # name the part that loops, as `cycle` does
            hint = refusal_hint(perf, perf, 0, 0)
            raise CycleError(f"{exc}" + (f"; {hint}" if hint else "")) from None
        loop = loop_clip(result, perf, name=clip.name)
        note = f"{motion.source.name}: extracted a {result.period:.3f} s loop from {result.cycles} cycles"
    if motion.unit_note:
        note += f"; {motion.unit_note}"
    if retarget:
        loop, family = to_puppet(loop, joint_map)
        note += f", retargeted to the puppet with the {family!r} map"
    # Edit in place, as the built-in cycles are: the travel rides in root motion.
    return loop.extract_root_motion(), note


def _loop_of_part(
    motion: MotionFile,
    start: Bound | None,
    end: Bound | None,
    items: list[str] | None,
) -> tuple[Clip, str]:
    """The loop extracted from the part ``[start, end)`` of a take (the refusal names the part that loops)."""
    from authoring.cycles.extract import CycleError, extract_cycle
    from authoring.cycles.formats import loop_clip, performance_from_motion
    from authoring.cycles.take_range import refusal_hint, select

    whole = performance_from_motion(motion, items)
    perf, offset = select(whole, start, end)
    try:
        result = extract_cycle(perf.trajectory, np.random.default_rng(0))
    except CycleError as exc:
        hint = refusal_hint(whole, perf, offset, 0)
        raise ValueError(f"{exc}" + (f"; {hint}" if hint else "")) from None
    note = (
        f"{motion.source.name}: extracted a {result.period:.3f} s loop from {result.cycles} cycles of the part picked"
    )
    return loop_clip(result, perf, name=motion.clip.name), note
