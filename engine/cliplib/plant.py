"""Feet that stay planted: removing a retargeted cycle's foot skate with the leg IK.

Mocap moved onto the puppet slides: its legs, ankles and soles are not the actor's, so
where the actor's heel stood still the puppet's creeps (≈0.15 m/s on the CMU walk),
while the built-in clips, solved from planted intent, do not slide at all. For each
foot the lowest sole point is followed across the heel-to-toe hand-over (the same
track :func:`engine.clips.foot_sliding` measures); while the foot is in contact its
horizontal drift is accumulated and subtracted from the ankle's target, and after
lift-off the correction fades out over the swing, so a pinned foot stays put and a
swinging foot rejoins its own path. The analytic leg IK the built-in clips use
(:mod:`engine.clips._legik`) then bends hip and knee to reach the target with the
foot's world orientation kept. Heights are untouched: only skating is removed.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from engine.arrays import F64 as F
from engine.clip import Clip
from engine.clips._legik import solve_leg
from engine.clips.contacts import foot_contacts, sole_points, world_poses

__all__ = ["plant_feet", "LEGS"]

LEGS = (("l_upper_leg", "l_lower_leg", "l_foot"), ("r_upper_leg", "r_lower_leg", "r_foot"))


def _drift(clip: Clip) -> F:
    """``[F, 2, 3]`` per-frame horizontal motion of each foot's lowest sole point, followed across hand-overs."""
    pts = sole_points(clip, closing=True)  # [F+1, side, heel/toe, 3]
    low = np.argmin(pts[..., 1], axis=-1)
    here = np.take_along_axis(pts[:-1], low[:-1, :, None, None], axis=2)[:, :, 0]
    there = np.take_along_axis(pts[1:], low[:-1, :, None, None], axis=2)[:, :, 0]
    d = there - here
    d[..., 1] = 0.0
    return d


def _correction(contact: NDArray[np.bool_], drift: F, fade: int) -> F:
    """Offset ``[F, 3]`` for one foot of a loop: minus the drift accumulated in contact, fading after lift-off.

    The loop is walked twice and the second pass kept, so a fade that runs across the
    seam is carried over as it would be when the cycle plays on.
    """
    n = len(contact)
    out = np.zeros((n, 3))
    acc, lift = np.zeros(3), np.zeros(3)
    since, before = fade, False
    for k in range(2 * n):
        i = k % n
        if contact[i]:
            if not before:  # landing: start from what is still applied
                acc = lift * max(0.0, 1.0 - since / fade)
            out[i] = acc
            acc = acc - drift[i]
        else:
            if before:  # lift-off: fade out what was accumulated
                lift, since = acc, 0
            since = min(since + 1, fade)
            out[i] = lift * (1.0 - since / fade)
        before = bool(contact[i])
    return out


def plant_feet(clip: Clip, iterations: int = 3, fade_seconds: float = 0.15) -> Clip:
    """``clip`` (a loop on the puppet's skeleton, root motion applied) with its planted feet pinned."""
    if not clip.loop:
        raise ValueError(f"clip {clip.name!r}: feet are planted on loops only")
    sk = clip.skeleton
    fade = max(1, int(round(fade_seconds * clip.fps)))
    for _ in range(iterations):
        contacts = foot_contacts(clip, max_speed=0.6)
        drift = _drift(clip)
        pos, wrot = world_poses(clip)
        rot = np.array(clip.rotations)
        for side, (upper, lower, foot) in enumerate(LEGS):
            u, lo, f = sk.index(upper), sk.index(lower), sk.index(foot)
            target = pos[:, f] + _correction(contacts[:, side], drift[:, side], fade)
            pole = pos[:, lo] - 0.5 * (pos[:, u] + pos[:, f])
            sol = solve_leg(
                pos[:, u],
                wrot[:, int(sk.parents[u])],
                target,
                pole,
                wrot[:, f],
                float(np.linalg.norm(sk.offsets[lo])),
                float(np.linalg.norm(sk.offsets[f])),
                max_reach=0.9995,
            )
            rot[:, u], rot[:, lo], rot[:, f] = sol.upper, sol.knee, sol.foot
        clip = replace(clip, rotations=rot)
    return clip
