"""``cycle --retarget puppet``: a skeletal performance moved onto the puppet before the loop is found.

Retargeting first (rather than the loop after) makes the extractor analyse the puppet's
17 joints — what will play — instead of the actor's 40-odd, and the loop it writes is a
``.ppclip``/BVH on the puppet's skeleton, ready for ``clips add``. The retarget
(:func:`engine.cliplib.source.to_puppet`) scales the root's travel by the leg-length
ratio, so the stride and the speed fit the puppet's legs, and puts the feet on y = 0; the
retargeted clip is then analysed exactly as a file on the puppet's skeleton would be
(:func:`~authoring.cycles.formats.performance_from_motion`: heading-normalised).
"""

from __future__ import annotations

from dataclasses import replace

from authoring.cycles.formats import Performance, performance_from_motion
from authoring.cycles.trajectory import TrajectoryError
from engine.cliplib.source import to_puppet
from engine.skeleton import Skeleton

__all__ = ["TARGETS", "retarget_performance"]

TARGETS = ("puppet",)


def retarget_performance(perf: Performance, target: Skeleton, joint_map: dict[str, str] | None = None) -> Performance:
    """``perf`` played by ``target`` (skeletal input only), through ``joint_map`` when one is given."""
    if perf.motion is None:
        raise TrajectoryError("--retarget needs skeletal input (BVH or glTF)")
    clip, _ = to_puppet(perf.motion.clip, target, joint_map)
    return performance_from_motion(replace(perf.motion, clip=clip))
