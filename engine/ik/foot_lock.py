"""Foot locking: a planted foot stays where it landed until its clip lifts it.

Blending clips, turning and speed changes move a planted foot a little every step
even when the root motion is exact (a blend of two planted feet at different places is
not planted anywhere). Engines fix it in the leg IK: when the animation's contact
labels say a foot is down, its toe tip is *locked* where it touched the ground and the
foot keeps the heading it landed with, and the two-bone leg solve reaches there; when
the label lifts it, the lock fades out over ``release_time`` (smoothstep), so the foot
eases back to its animated path instead of snapping. A lock that would stretch the leg
beyond ``max_stretch`` or twist it beyond ``max_twist`` (a sharp turn, a yank) lets go the
same way. When the puppet comes to stand, a foot left away from where the standing pose
wants it takes a step there (one foot at a time), as a person shuffles into stance,
instead of creeping or hovering.

The toe tip is the locked point because it is what stays still longest in a step
(heel-off rolls over it) and what an onlooker sees skate; the heading is locked too, or
a foot turning with the hips would sweep its heel over the ground. A lock fades only
once the toe is really off the floor (``release_height``): contact labels end while the
toe still pushes off. Only the ground plane position and heading are locked; heights
stay the grounding's (clip clearance over the real ground) plus the arc of a step, then
:func:`floor_lift` keeps toe and heel above the floor.

All functions work on arrays ``[P, L, …]`` (puppets, legs) so a crowd locks its feet
in one call; the state lives in :class:`FootLock` on the request (hashed, replayed).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

__all__ = ["FootLock", "lock_feet", "floor_lift", "smoothstep"]

from engine.arrays import F64 as F


@dataclass
class FootLock:
    """Per-puppet lock state: where each leg's toe is held and how strongly.

    Attributes:
        contacts: the animation's contact vote per leg this step (0 swing … 1 planted),
            written by the animation stage; ``None`` turns locking off.
        points: ``[L, 3]`` locked toe tips (world), meaningful where ``weights > 0``.
        weights: ``[L]`` lock strength in ``[0, 1]`` (1 while planted, fading after).
        planted: ``[L]`` whether each leg is in its contact phase (the lock was taken).
        settle: written by the animation stage: the puppet is asked to stand still.
        stepping: ``[L]`` a standing puppet's foot on its way to its place.
        animated: ``[L, 3]`` last step's animated toe tips (is the standing place still moving?).
        yaw: ``[L]`` the heading each locked foot landed with (it keeps it while planted).
        release_time: seconds a lock takes to fade after its foot lifts.
        max_stretch: metres the locked toe may be from the animated one before it lets go.
        release_height: metres the animated toe must rise before a lifted foot's lock fades.
        settle_gap: metres a standing puppet's foot may be from its place before it steps there.
        max_twist, settle_twist: the same in heading (rad) for a moving and a standing puppet.
        step_time, step_height: how long (s) and how high (m, at most) such a step is.
        enabled: off, planted feet follow the animation (the legacy controller's behaviour).
    """

    contacts: F | None = None
    points: F = field(default_factory=lambda: np.zeros((0, 3)))
    weights: F = field(default_factory=lambda: np.zeros(0))
    planted: NDArray[np.bool_] = field(default_factory=lambda: np.zeros(0, dtype=bool))
    settle: bool = False
    stepping: NDArray[np.bool_] = field(default_factory=lambda: np.zeros(0, dtype=bool))
    animated: F = field(default_factory=lambda: np.zeros((0, 3)))
    yaw: F = field(default_factory=lambda: np.zeros(0))
    release_time: float = 0.12
    max_stretch: float = 0.12
    release_height: float = 0.035
    settle_gap: float = 0.05
    max_twist: float = 0.6
    settle_twist: float = 0.25
    step_time: float = 0.3
    step_height: float = 0.08
    enabled: bool = True

    def settings(self) -> tuple[float, ...]:
        """The lock's tuning (not its state): puppets that share it are locked in one array pass."""
        return (
            self.release_time,
            self.max_stretch,
            self.release_height,
            self.settle_gap,
            self.max_twist,
            self.settle_twist,
            self.step_time,
            self.step_height,
        )


_TOE = 0.15  # m from the ankle to the toe tip: what a turn of the foot moves its end by, per radian


def smoothstep(w: F) -> F:
    """``3w² − 2w³``: eases a weight in ``[0, 1]`` in and out with zero slope at both ends."""
    return w * w * (3.0 - 2.0 * w)


def lock_feet(
    points: F,
    weights: F,
    planted: NDArray[np.bool_],
    stepping: NDArray[np.bool_],
    toes: F,
    contacts: F,
    clearance: F,
    twist: F,
    settle: NDArray[np.bool_],
    still: NDArray[np.bool_],
    dt: float,
    lock: FootLock,
) -> tuple[F, F, NDArray[np.bool_], NDArray[np.bool_], F]:
    """Advance the locks one step and say where each toe should go.

    Args:
        points, weights, planted, stepping: the lock state ``[P, L, 3]``, ``[P, L]``, ``[P, L]``,
            ``[P, L]`` (``stepping``: a standing puppet's foot on its way to its place).
        toes: ``[P, L, 3]`` where the animation (after grounding) puts each toe tip.
        contacts: ``[P, L]`` contact votes; above 0.5 a foot is planted.
        clearance: ``[P, L]`` the animated toe's height above the ground: a planted toe stays
            locked until it is ``release_height`` up, even after its label lifted (labels end
            while the toe still pushes off the floor).
        twist: ``[P, L]`` how far (rad) each locked foot's heading is from the animation's: past
            ``max_twist`` it lets go like a stretched one (a standing puppet's steps past
            ``settle_twist``), since a foot keeps its heading while locked.
        settle: ``[P]`` the puppet is coming to stand: a foot held more than ``settle_gap``
            from where the standing pose wants it takes a step there, one foot at a time,
            once that place has stopped moving (``still [P, L]``: the blend has settled).
        lock: the settings (``release_time``, ``max_stretch``, ``settle_gap``, ``step_time``,
            ``step_height``).

    Returns:
        ``(points, weights, planted, stepping, targets)``: the new state and ``[P, L, 3]`` toe
        targets: x and z pulled to the locks; a fading lock's foot lifted on a low arc (it
        was let go far from its animated place), a stepping foot rising first, moving in the
        middle of its step and setting down at the end, so feet step, never slide.
    """
    down = contacts > 0.5
    # A step ends when the foot has arrived, or when the puppet sets off again (it plants where it is).
    stepping = stepping & (weights > 0.0) & settle[:, None]
    shown = toes + smoothstep(weights)[..., None] * (points - toes)
    shown[..., 1] = toes[..., 1]
    start = down & ~planted & ~stepping
    # A lock taken while an old one still fades starts where the foot is shown: no pop.
    points = np.where(start[..., None], shown, points)
    weights = np.where(start, 1.0, weights)
    # How far the foot has to go, its turn counted at a toe's length from the ankle.
    gap = np.linalg.norm((points - toes)[..., [0, 2]], axis=-1) + _TOE * np.where(start, 0.0, twist)
    held = planted | start
    # Standing, a far foot waits for its step (one foot at a time) instead of letting go.
    stretched = ((gap > lock.max_stretch) | (twist > lock.max_twist)) & ~start & ~settle[:, None]
    # Standing: the farthest misplaced foot steps, if no foot of the puppet is stepping already.
    misplaced = held & settle[:, None] & still & ((gap > lock.settle_gap) | (twist > lock.settle_twist))
    first = misplaced & (gap >= np.max(np.where(misplaced, gap, 0.0), axis=-1, keepdims=True))
    step_now = first & ~np.any(stepping, axis=-1, keepdims=True)
    stepping = stepping | step_now
    holding = down | (planted & (clearance < lock.release_height))
    planted = holding & ~stretched & held & ~stepping
    fading = ~planted
    rate = np.where(stepping, dt / lock.step_time, dt / lock.release_time)
    weights = np.where(fading, np.maximum(weights - rate, 0.0), weights)
    progress = 1.0 - weights
    along = np.where(stepping, 1.0 - smoothstep(np.clip((progress - 0.25) / 0.5, 0.0, 1.0)), smoothstep(weights))
    targets = toes + along[..., None] * (points - toes)
    lift = np.where(
        stepping,
        np.sin(np.pi * progress) * np.minimum(0.5 * gap + 0.04, lock.step_height),
        np.where(fading, 4.0 * weights * (1.0 - weights) * np.minimum(0.5 * gap, lock.step_height), 0.0),
    )
    targets[..., 1] = toes[..., 1] + lift
    return points, weights, planted, stepping, targets


def floor_lift(heights: F, ground: F) -> F:
    """How much to raise each foot ``[P, L]`` so that none of its points ``heights [P, L, N]`` is below ``ground [P, L]``."""
    return np.maximum(ground - heights.min(axis=-1), 0.0)
