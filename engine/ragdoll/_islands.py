"""Which ragdolls the MuJoCo model must hold this step: animated puppets cost no dynamics.

An *animated* ragdoll is placed on its animation every step: its bodies never move by
themselves, so simulating them is wasted work — 46 degrees of freedom, 40 servos and
8 substeps per puppet, every step, only to be overwritten. It needs to be in the model
only when something simulated could touch it, because it pushes props and simulated
ragdolls (and they do not push it). So the model holds every simulated ragdoll (active,
limp, held) and every prop, and an animated ragdoll only while one of those is near
it: bounding spheres (the ragdoll's reach around its root, a prop's radius plus how
far it travels in :data:`LOOKAHEAD`) closer than :data:`ENTER`, kept until farther
than :data:`LEAVE` (the hysteresis keeps a puppet walking beside a ball from
swapping pool slots every step). A crowd walking on an empty field is then no
MuJoCo work at all; joining or leaving borrows or returns a slot of the ragdoll pool
(:mod:`engine.ragdoll._pool`), a state copy, not a compile.

Spheres that hold a ragdoll in *any* pose are loose: a standing puppet's is ~2 m wide for a
body 0.5 m wide, and ten puppets falling in a crowd of a hundred pulled some fifty walking
neighbours into the model (each costs as much MuJoCo work as a faller). So the spheres only
pick the candidates; a candidate joins when the axis-aligned boxes of the capsules in their
*current* poses (:func:`capsule_boxes`, :func:`box_gaps`) are also that close. Both are lower
bounds of the true distance between the bodies, so the larger of the two is too.

Puppets can also end up inside each other (two dropped on one spot, one walked into
another as it falls): MuJoCo would push them apart at 10⁵ m/s. A simulated ragdoll whose
root is that close to another's is a *ghost* (:func:`ghosts`): it touches only the
ground and props until the two are apart again.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from engine.arrays import F64 as _F
from engine.ragdoll.profile import RagdollProfile, bone_segments
from engine.skeleton import Skeleton

__all__ = [
    "reach",
    "near_simulated",
    "capsule_boxes",
    "box_gaps",
    "near_boxes",
    "ghosts",
    "ENTER",
    "LEAVE",
    "LOOKAHEAD",
    "OVERLAP",
    "APART",
]

# m of clearance (between bounding spheres, then boxes) under which an animated ragdoll joins. It must
# cover how far the two can close in one step (a limb swinging at 5 m/s and a body falling at 4 m/s
# close 0.15 m in 1/60 s): nearer than that it might touch before the next test. It was 0.4 m with
# LEAVE 1.0 m, which kept every walker that had once passed within 0.4 m of a fallen puppet in the
# model for the next metre: ten of a hundred falling then held 20-28 walking neighbours (as much
# MuJoCo work per neighbour as per faller), of which two or three touched anything.
ENTER = 0.15
LEAVE = 0.3  # m of clearance over which it leaves again (the hysteresis: no slot swap every step)
LOOKAHEAD = 0.25  # s of a prop's travel added to its sphere
OVERLAP = 0.35  # m between two roots under which a simulated ragdoll passes through ragdolls (a ghost)
APART = 0.8  # m over which a ghost collides with ragdolls again


def reach(skeleton: Skeleton, profile: RagdollProfile, offsets: _F) -> float:
    """Radius around the root joint of a sphere that holds the ragdoll in any pose."""
    _, _, r = bone_segments(skeleton, profile.radii, offsets)
    # the chain length from the root bounds a joint's distance in every pose, not just at rest
    chain = np.zeros(skeleton.num_joints)
    for j in range(1, skeleton.num_joints):
        chain[j] = chain[int(skeleton.parents[j])] + float(np.linalg.norm(offsets[j]))
    tips = np.linalg.norm(np.asarray(skeleton.tips, dtype=np.float64), axis=1)
    return float(np.max(chain + tips + r))


def near_simulated(
    centres: _F, radii: _F, sources: _F, source_radii: _F, inside: NDArray[np.bool_]
) -> NDArray[np.bool_]:
    """Which animated ragdolls (spheres ``centres [A,3]``, ``radii [A]``) are near a simulated
    body or prop (``sources [S,3]``, ``source_radii [S]``); ``inside [A]`` says which are in the
    model now (they stay until :data:`LEAVE`, the others join under :data:`ENTER`)."""
    if len(centres) == 0 or len(sources) == 0:
        return np.zeros(len(centres), dtype=bool)
    gap = np.linalg.norm(centres[:, None, :] - sources[None, :, :], axis=2) - radii[:, None] - source_radii[None, :]
    limit = np.where(inside, LEAVE, ENTER)
    return np.asarray((gap < limit[:, None]).any(axis=1))


def capsule_boxes(a: _F, b: _F, r: _F, owner: NDArray[np.int64], count: int) -> _F:
    """Axis-aligned boxes ``[count, 2, 3]`` (low, high corners) around capsules from ``a [N,3]`` to
    ``b [N,3]`` of radius ``r [N]``, capsule ``i`` belonging to box ``owner[i]`` (owners sorted)."""
    lo = np.minimum(a, b) - r[:, None]
    hi = np.maximum(a, b) + r[:, None]
    out = np.empty((count, 2, 3))
    starts = np.searchsorted(owner, np.arange(count))
    out[:, 0] = np.minimum.reduceat(lo, starts, axis=0)
    out[:, 1] = np.maximum.reduceat(hi, starts, axis=0)
    return out


def box_gaps(boxes: _F, others: _F) -> _F:
    """Distance ``[A,S]`` between each of ``boxes [A,2,3]`` and each of ``others [S,2,3]`` (0 when they overlap)."""
    sep = np.maximum(others[None, :, 0] - boxes[:, None, 1], boxes[:, None, 0] - others[None, :, 1])
    return np.asarray(np.linalg.norm(np.maximum(sep, 0.0), axis=2))


def near_boxes(boxes: _F, sources: _F, inside: NDArray[np.bool_]) -> NDArray[np.bool_]:
    """:func:`near_simulated` for boxes: which of ``boxes [A,2,3]`` are near one of ``sources [S,2,3]``,
    with the same hysteresis (``inside [A]``: in the model now)."""
    if len(boxes) == 0 or len(sources) == 0:
        return np.zeros(len(boxes), dtype=bool)
    limit = np.where(inside, LEAVE, ENTER)
    return np.asarray((box_gaps(boxes, sources) < limit[:, None]).any(axis=1))


def ghosts(roots: _F, simulated: NDArray[np.bool_], ghost: NDArray[np.bool_]) -> NDArray[np.bool_]:
    """Which simulated ragdolls (roots ``[P,3]``) are deep inside another ragdoll: roots closer
    than :data:`OVERLAP`; a ghost (``ghost [P]`` now) stays one until farther than :data:`APART`."""
    if len(roots) < 2:
        return np.zeros(len(roots), dtype=bool)
    dist = np.linalg.norm(roots[:, None, :] - roots[None, :, :], axis=2)
    np.fill_diagonal(dist, np.inf)
    limit = np.where(ghost, APART, OVERLAP)
    return np.asarray(simulated & (dist.min(axis=1) < limit))
