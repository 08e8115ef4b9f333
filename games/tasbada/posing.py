"""The avatar starts in the player's pose and eases into its own idle (AR Poser's hand-over).

:class:`SelfiePose` rides on the avatar from the moment it appears: the local rotations
lifted from the selfie (:func:`games.tasbada.pose.lift`), the joints they pose, and when it
appeared. :func:`selfie_pose_system` runs in the ``animation`` stage after the puppet's
own blending: for :data:`HOLD` seconds the posed joints take the selfie's rotations,
then over :data:`BLEND` seconds they slerp back to whatever the animation says (idle,
or walking once the person grabs the avatar). Simulation state: hashed, replayed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from engine import quat
from engine.components import LocalPose
from engine.ecs import World

__all__ = ["SelfiePose", "selfie_pose_system", "weight", "HOLD", "BLEND"]

HOLD = 2.0
"""Seconds the avatar holds the player's pose."""
BLEND = 1.5
"""Seconds it then takes to ease into the animation."""


@dataclass
class SelfiePose:
    """The player's pose on the avatar: local rotations ``[J,4]``, posed joints ``[J]``, start time."""

    rotations: NDArray[np.float64]
    posed: NDArray[np.bool_]
    start: float


def weight(t: float) -> float:
    """How much of the selfie's pose shows ``t`` seconds after the avatar appeared (1 → 0, smooth)."""
    x = min(max((t - HOLD) / BLEND, 0.0), 1.0)
    return 1.0 - x * x * (3.0 - 2.0 * x)


def selfie_pose_system(world: World) -> None:
    """Blend each avatar's animated pose towards its selfie pose by :func:`weight`."""
    now = world.time
    for _, sp, pose in world.query(SelfiePose, LocalPose):
        w = weight(now - sp.start)
        if w <= 0.0 or not sp.posed.any():
            continue
        j = sp.posed
        pose.rotations = np.array(pose.rotations)
        pose.rotations[j] = quat.slerp(pose.rotations[j], sp.rotations[j], w)
