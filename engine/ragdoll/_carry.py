"""Carrying simulation state across a model rebuild, by name.

A rebuild (a ragdoll or prop added or removed) compiles a new model whose addresses
all move. What survives is names: every joint keeps its qpos, qvel and solver warm
start, every mocap body its pose, every equality constraint its active flag. New
bodies are placed by the caller afterwards.
"""

from __future__ import annotations

import mujoco
import numpy as np
from numpy.typing import NDArray

__all__ = ["snapshot", "restore"]

Snapshot = dict[str, dict[str, NDArray[np.float64]]]
_SIZES = {int(mujoco.mjtJoint.mjJNT_FREE): (7, 6), int(mujoco.mjtJoint.mjJNT_BALL): (4, 3)}


def snapshot(m: mujoco.MjModel | None, d: mujoco.MjData | None) -> Snapshot:
    """Every joint's, mocap body's and constraint's state keyed by name (empty without a model)."""
    snap: Snapshot = {"joint": {}, "mocap": {}, "eq": {}}
    if m is None or d is None:
        return snap
    for j in range(m.njnt):
        q0, v0 = m.jnt_qposadr[j], m.jnt_dofadr[j]
        nq, nv = _SIZES.get(int(m.jnt_type[j]), (1, 1))
        snap["joint"][m.joint(j).name] = np.concatenate(
            [d.qpos[q0 : q0 + nq], d.qvel[v0 : v0 + nv], d.qacc_warmstart[v0 : v0 + nv]]
        )
    for b in np.nonzero(m.body_mocapid >= 0)[0]:
        i = m.body_mocapid[b]
        snap["mocap"][m.body(int(b)).name] = np.concatenate([d.mocap_pos[i], d.mocap_quat[i]])
    for e in range(m.neq):
        snap["eq"][m.eq(e).name] = np.array([d.eq_active[e]], dtype=np.float64)
    return snap


def restore(m: mujoco.MjModel, d: mujoco.MjData, snap: Snapshot) -> None:
    """Write a :func:`snapshot` into a freshly compiled model's data, name by name."""
    for j in range(m.njnt):
        saved = snap["joint"].get(m.joint(j).name)
        if saved is None:
            continue
        q0, v0 = m.jnt_qposadr[j], m.jnt_dofadr[j]
        nq, nv = _SIZES.get(int(m.jnt_type[j]), (1, 1))
        d.qpos[q0 : q0 + nq] = saved[:nq]
        d.qvel[v0 : v0 + nv] = saved[nq : nq + nv]
        d.qacc_warmstart[v0 : v0 + nv] = saved[nq + nv :]
    for b in np.nonzero(m.body_mocapid >= 0)[0]:
        saved = snap["mocap"].get(m.body(int(b)).name)
        if saved is not None:
            d.mocap_pos[m.body_mocapid[b]] = saved[:3]
            d.mocap_quat[m.body_mocapid[b]] = saved[3:]
    for e in range(m.neq):
        saved = snap["eq"].get(m.eq(e).name)
        if saved is not None:
            d.eq_active[e] = int(saved[0])
