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

__all__ = ["reach", "near_simulated", "ghosts", "ENTER", "LEAVE", "LOOKAHEAD", "OVERLAP", "APART"]

ENTER = 0.4  # m of clearance between bounding spheres under which an animated ragdoll joins
LEAVE = 1.0  # m of clearance over which it leaves again
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


def ghosts(roots: _F, simulated: NDArray[np.bool_], ghost: NDArray[np.bool_]) -> NDArray[np.bool_]:
    """Which simulated ragdolls (roots ``[P,3]``) are deep inside another ragdoll: roots closer
    than :data:`OVERLAP`; a ghost (``ghost [P]`` now) stays one until farther than :data:`APART`."""
    if len(roots) < 2:
        return np.zeros(len(roots), dtype=bool)
    dist = np.linalg.norm(roots[:, None, :] - roots[None, :, :], axis=2)
    np.fill_diagonal(dist, np.inf)
    limit = np.where(ghost, APART, OVERLAP)
    return np.asarray(simulated & (dist.min(axis=1) < limit))
