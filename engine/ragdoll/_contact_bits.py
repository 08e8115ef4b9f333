"""Contact bits written at run time, on geoms and on their bodies alike.

MuJoCo filters pairs twice: per geom (``geom_contype``/``geom_conaffinity``) and, in its
broad phase, per body (``body_contype``/``body_conaffinity``: the OR of the body's geoms'
bits, computed when the model is compiled). A pool slot compiled parked (every bit zero) and
later given contacts on its geoms alone keeps zero body bits, so the broad phase drops every
pair: the ragdoll falls through the ground. Every run-time change of contact bits goes
through :func:`set_contact_bits`, which keeps the body aggregates true.
"""

from __future__ import annotations

import mujoco
import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["set_contact_bits"]


def set_contact_bits(m: mujoco.MjModel, geoms: NDArray[np.int64], contype: ArrayLike, conaffinity: ArrayLike) -> None:
    """Give ``geoms`` these bits (scalars or one per geom) and recompute the aggregates of the bodies
    whose geoms changed. Called every physics step, where usually nothing changes: then it only compares."""
    geoms = np.asarray(geoms, dtype=np.int64)
    new_type = np.broadcast_to(np.asarray(contype, dtype=m.geom_contype.dtype), geoms.shape)
    new_affinity = np.broadcast_to(np.asarray(conaffinity, dtype=m.geom_conaffinity.dtype), geoms.shape)
    changed = (m.geom_contype[geoms] != new_type) | (m.geom_conaffinity[geoms] != new_affinity)
    if not changed.any():
        return
    geoms = geoms[changed]
    m.geom_contype[geoms] = new_type[changed]
    m.geom_conaffinity[geoms] = new_affinity[changed]
    bodies = np.unique(m.geom_bodyid[geoms])
    of_bodies = np.nonzero(np.isin(m.geom_bodyid, bodies))[0]  # every geom of those bodies, not only these
    owner = m.geom_bodyid[of_bodies]
    m.body_contype[bodies] = 0
    m.body_conaffinity[bodies] = 0
    np.bitwise_or.at(m.body_contype, owner, m.geom_contype[of_bodies])
    np.bitwise_or.at(m.body_conaffinity, owner, m.geom_conaffinity[of_bodies])
