"""Orientation handles on a Motion Curve (thesis Fig. 4.4, middle): where they are drawn and what a drag means.

At every frame the curve shows the selected joint's heading: a short stick from the
trajectory point along the joint's bone (its first child's offset, or its tip for a leaf),
in the joint's world orientation at that frame. The current frame's stick ends in a grip;
dragging the grip on the view plane turns the joint by the shortest arc from the stick's
direction to the grip's, which the editor asks of the tangent solver (between keys) or of
the static IK (at a key).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from engine import quat
from engine.skeleton import Skeleton

if TYPE_CHECKING:
    from authoring.keyframe_curves.session import CurveSession

__all__ = ["bone_axis", "HANDLE_LENGTH", "ORIENT_RGB", "turn_towards", "orientation_sticks"]

from engine.arrays import F64 as F

HANDLE_LENGTH = 0.08  # metres
ORIENT_RGB = (0.1, 0.75, 0.7)


def bone_axis(skeleton: Skeleton, joint: int) -> F:
    """``[3]`` unit direction of ``joint``'s bone in its own frame (first child's offset, else its tip, else +y)."""
    children = np.nonzero(skeleton.parents == joint)[0]
    axis = skeleton.offsets[children[0]] if children.size else skeleton.tips[joint]
    n = float(np.linalg.norm(axis))
    return axis / n if n > 1e-9 else np.array([0.0, 1.0, 0.0])


def turn_towards(world_rotation: F, axis_local: F, direction: F) -> F:
    """The world orientation that turns the bone's axis by the shortest arc onto ``direction``."""
    now = quat.rotate(world_rotation, axis_local)
    return quat.normalize(quat.mul(quat.between(now, direction), world_rotation))


def orientation_sticks(session: CurveSession, times: F, joint: int) -> tuple[F, F, F]:
    """``(base [T,3], tip [T,3], world rotation [T,4])`` of ``joint``'s handle at ``times``."""
    from authoring.keyframe_curves.jacobian import _fk

    wp, wm = _fk(session.solver.rig, session.clip.coordinates(times))
    base = wp[:, joint]
    axis = bone_axis(session.clip.skeleton, joint)
    tip = base + HANDLE_LENGTH * (wm[:, joint] @ axis)
    return base, tip, quat.from_matrix(wm[:, joint])
