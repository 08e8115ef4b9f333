"""Foot locking: a planted foot stays where it landed until its clip lifts it.

Blending clips, turning and speed changes move a planted foot a little every step
even when the root motion is exact (a blend of two planted feet at different places is
not planted anywhere). Engines fix it in the leg IK: when the animation's contact
labels say a foot is down, its toe tip is *locked* at the point where it touched the
ground, and the two-bone leg solve reaches there; when the label lifts it, the lock
fades out over ``release_time`` (smoothstep), so the foot eases back to its animated
path instead of snapping. A lock that would stretch the leg beyond ``max_stretch``
from the animated foot (a sharp turn, a yank) lets go the same way.

The toe tip is the locked point because it is what stays still longest in a step
(heel-off rolls over it) and what an onlooker sees skate. A lock fades only once the
toe is really off the floor (``release_height``): contact labels end while the toe
still pushes off. Only the ground-plane
position is locked (a releasing foot far from its animated place steps there on a low
arc); heights stay the grounding's (clip clearance over the real
ground), then :func:`floor_lift` keeps toe and heel above the floor.

All functions work on arrays ``[P, L, …]`` (puppets, legs) so a crowd locks its feet
in one call; the state lives in :class:`FootLock` on the request (hashed, replayed).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

__all__ = ["FootLock", "lock_feet", "floor_lift"]

F = NDArray[np.float64]


@dataclass
class FootLock:
    """Per-puppet lock state: where each leg's toe is held and how strongly.

    Attributes:
        contacts: the animation's contact vote per leg this step (0 swing … 1 planted),
            written by the animation stage; ``None`` turns locking off.
        points: ``[L, 3]`` locked toe tips (world), meaningful where ``weights > 0``.
        weights: ``[L]`` lock strength in ``[0, 1]`` (1 while planted, fading after).
        planted: ``[L]`` whether each leg is in its contact phase (the lock was taken).
        release_time: seconds a lock takes to fade after its foot lifts.
        max_stretch: metres the locked toe may be from the animated one before it lets go.
        release_height: metres the animated toe must rise before a lifted foot's lock fades.
        enabled: off, planted feet follow the animation (the legacy controller's behaviour).
    """

    contacts: F | None = None
    points: F = field(default_factory=lambda: np.zeros((0, 3)))
    weights: F = field(default_factory=lambda: np.zeros(0))
    planted: NDArray[np.bool_] = field(default_factory=lambda: np.zeros(0, dtype=bool))
    release_time: float = 0.12
    max_stretch: float = 0.12
    release_height: float = 0.035
    enabled: bool = True


def _smooth(w: F) -> F:
    return w * w * (3.0 - 2.0 * w)


def lock_feet(points: F, weights: F, planted: NDArray[np.bool_], toes: F, contacts: F, clearance: F, dt: float,
              release_time: float, max_stretch: float, release_height: float,
              step_height: float = 0.08) -> tuple[F, F, NDArray[np.bool_], F]:
    """Advance the locks one step and say where each toe should go.

    Args:
        points, weights, planted: the lock state ``[P, L, 3]``, ``[P, L]``, ``[P, L]``.
        toes: ``[P, L, 3]`` where the animation (after grounding) puts each toe tip.
        contacts: ``[P, L]`` contact votes; above 0.5 a foot is planted.
        clearance: ``[P, L]`` the animated toe's height above the ground: a planted toe stays
            locked until it is ``release_height`` up, even after its label lifted (labels end
            while the toe still pushes off the floor).

    Returns:
        ``(points, weights, planted, targets)``: the new state and ``[P, L, 3]`` toe targets:
        x and z pulled to the locks, and a fading lock's foot lifted on an arc of up to
        ``step_height`` (half the distance it still has to go), so it steps, not slides.
    """
    down = contacts > 0.5
    shown = toes + _smooth(weights)[..., None] * (points - toes)
    shown[..., 1] = toes[..., 1]
    start = down & ~planted
    # A lock taken while an old one still fades starts where the foot is shown: no pop.
    points = np.where(start[..., None], shown, points)
    weights = np.where(start, 1.0, weights)
    stretched = np.linalg.norm((points - toes)[..., [0, 2]], axis=-1) > max_stretch
    holding = down | (planted & (clearance < release_height))
    planted = holding & ~stretched & (planted | start)
    fading = ~planted
    weights = np.where(fading, np.maximum(weights - dt / release_time, 0.0), weights)
    targets = toes + _smooth(weights)[..., None] * (points - toes)
    # A foot let go far from where the animation wants it (the puppet stopped or turned
    # mid-stride) steps there: it rises on an arc while it moves instead of sliding.
    gap = np.linalg.norm((points - toes)[..., [0, 2]], axis=-1)
    arc = np.where(fading, 4.0 * weights * (1.0 - weights) * np.minimum(0.5 * gap, step_height), 0.0)
    targets[..., 1] = toes[..., 1] + arc
    return points, weights, planted, targets


def floor_lift(heights: F, ground: F) -> F:
    """How much to raise each foot ``[P, L]`` so that none of its points ``heights [P, L, N]`` is below ``ground [P, L]``."""
    return np.maximum(ground - heights.min(axis=-1), 0.0)
