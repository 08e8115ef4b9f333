"""The extractor's root-position curve in the loop clip's frame, for MoCurves to open (SCA 2017 §4–5).

The extractor fits the root position of skeletal input in the heading-normalised body
frame (:mod:`authoring.cycles.heading`) with its travel ramp taken out; the loop clip's
root is that path turned back to the world. Spline control points move with any affine
map, so the curve is carried over exactly by the rigid map that :func:`~authoring.cycles.
heading.restore` applies when the heading holds still: a turn about +Y by the loop's mean
heading around the loop's first root position. When the heading does not hold still the
world root is a different curve: measured on the CMU 16_15 walk (heading sways 7° per
stride), the carried curve misses the world root by 23 mm sideways where the extractor's
own fit is within 0.63 mm of the body-frame path. A curve that misses the clip's root by
more than :data:`MAX_MISFIT` times the extractor's bound is therefore not stored, and
MoCurves fits its own, as for any clip without one; loops without heading sway (in-place
motions, a straight treadmill walk, recorded layers) carry the extracted curve exactly.

Only the root position is carried: the extractor's rotation curves (tangent-space Béziers
around a mean quaternion) have no counterpart in MoCurves, which edits rotations with the
per-keypoint arrows and never control points, so nothing would read them.
"""

from __future__ import annotations

import numpy as np

from authoring.cycles.extract import CycleResult
from authoring.cycles.formats import Performance, loop_travel
from engine import quat
from engine.clip import Clip
from engine.root_curve import RootCurve

__all__ = ["MAX_MISFIT", "loop_root_curve"]

MAX_MISFIT = 2.0
"""A carried-over curve may miss the clip's root by at most this many times the extractor's own bound."""

_UP = np.array([0.0, 1.0, 0.0])


def loop_root_curve(result: CycleResult, perf: Performance, clip: Clip) -> RootCurve | None:
    """The extracted root-position curve in ``clip``'s frame, or None when it does not describe its root.

    ``clip`` is :func:`~authoring.cycles.formats.loop_clip` of the same result and performance.
    """
    if perf.clip is None:
        return None
    curve = result.curves.get(f"{perf.clip.skeleton.names[0]}.position")
    if curve is None or curve.segments > clip.num_frames:
        return None
    control, travel = curve.closed_control(), result.travel[0:3]
    if perf.heading is not None:
        h = perf.heading
        mean = float(np.arctan2(np.sin(result.loop[:, h]).mean(), np.cos(result.loop[:, h]).mean()))
        turn = quat.from_axis_angle(_UP, np.array(mean))
        start = result.loop[0, 0:3]
        control = quat.rotate(turn, control - start) + start
        travel = loop_travel(result, perf)[0]
    root_curve = RootCurve(control, travel)
    span = float(np.max(np.ptp(clip.root - root_curve.ramp(clip.num_frames), axis=0)))
    bound = MAX_MISFIT * max(curve.max_error, 0.01 * span)
    misfit = float(np.max(np.abs(root_curve.positions(clip.num_frames) - clip.root)))
    return root_curve if misfit <= bound else None
