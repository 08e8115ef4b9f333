"""Heading-normalised locomotion: cycles measured with the root's yaw and travel taken out.

A walk that turns (a curve, a figure eight) is the same stride over and over, but its raw
pose is not: the root rotation and the root position keep changing with the heading, so
cycles compared on them differ wildly and the take is refused as "cycles too different".
:func:`normalise` therefore rewrites skeletal input before extraction (paper §4 runs on
whatever N-D curve it is given; non-skeletal input keeps its raw curve):

* the root rotation loses its yaw about +Y, which becomes a travelling 1-D item
  ``heading`` (radians, unwrapped), so its per-cycle change is kept like travel;
* the root position becomes the path walked *in the body's frame*: ground-plane steps
  rotated by minus the heading and summed (a circle becomes a straight line), height as is.

:func:`restore` turns a loop measured that way back into world terms: yaw put back on the
root rotation and the steps turned by the heading again; a cycle's net turn and travel
come back as the closing frame's offset (:func:`engine.io.loop_export.closed`).
"""

from __future__ import annotations

import numpy as np

from engine import quat

__all__ = ["normalise", "restore", "yaw"]

from engine.arrays import F64

_UP = np.array([0.0, 1.0, 0.0])


def yaw(q: F64) -> F64:
    """Heading about +Y of rotations: the angle of their rotated +Z axis in the ground plane."""
    fwd = quat.rotate(q, np.array([0.0, 0.0, 1.0]))
    return np.arctan2(fwd[..., 0], fwd[..., 2])


def normalise(root: F64, root_rot: F64) -> tuple[F64, F64, F64]:
    """``(local_root [F,3], level_rot [F,4], heading [F])`` of a root track (see the module docstring)."""
    heading = np.unwrap(yaw(root_rot))
    level = quat.mul(quat.from_axis_angle(_UP, -heading), root_rot)
    steps = np.diff(root, axis=0)
    steps[:, 1] = 0.0
    mid = 0.5 * (heading[1:] + heading[:-1])
    local_steps = quat.rotate(quat.from_axis_angle(_UP, -mid), steps)
    local = np.concatenate([np.zeros((1, 3)), np.cumsum(local_steps, axis=0)])
    local[:, 1] = root[:, 1]
    return local, level, heading


def restore(local: F64, level: F64, heading: F64, travel: F64, turn: float) -> tuple[F64, F64, F64]:
    """World ``(root [S,3], root_rot [S,4], travel [3])`` of a normalised loop.

    ``travel`` is the loop's per-cycle travel in the body frame and ``turn`` its per-cycle
    heading change; the returned travel is the world offset from the first frame to the
    first frame of the next cycle.
    """
    ends = np.concatenate([local, (local[0] + travel)[None]])
    head = np.append(heading, heading[0] + turn)
    steps = np.diff(ends, axis=0)
    steps[:, 1] = 0.0
    mid = 0.5 * (head[1:] + head[:-1])
    world_steps = quat.rotate(quat.from_axis_angle(_UP, mid), steps)
    path = np.concatenate([np.zeros((1, 3)), np.cumsum(world_steps, axis=0)])
    path[:, 1] = np.append(local[:, 1], local[0, 1] + travel[1])
    start = np.array([local[0, 0], 0.0, local[0, 2]])
    path[:, [0, 2]] += start[[0, 2]]
    rot = quat.mul(quat.from_axis_angle(_UP, heading), level)
    return path[:-1], rot, path[-1] - path[0]
