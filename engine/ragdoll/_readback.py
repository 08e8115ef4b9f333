"""Reading the physics world back: poses, joint positions, velocities, energies, limit excess.

A mixin of :class:`~engine.ragdoll.physics.PhysicsWorld`, apart because it only reads.
A ragdoll left out of the model (animated, nothing simulated near:
:mod:`engine.ragdoll._islands`) is exactly on its target, so its answers come from its
command instead of MuJoCo's state.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import mujoco
import numpy as np

from engine import quat
from engine.arrays import F64 as _F
from engine.fk import forward_kinematics
from engine.pose import Pose
from engine.ragdoll._commands import Commands, joint_rows
from engine.ragdoll._control import read_poses
from engine.ragdoll._layout import Layout
from engine.ragdoll._slots import RagdollSlot

__all__ = ["Readback"]


class Readback:
    """Read-only queries over the compiled model of a physics world."""

    model: mujoco.MjModel | None
    data: mujoco.MjData | None
    layout: Layout | None
    _ke: _F | None
    _read: tuple[_F, _F] | None

    if TYPE_CHECKING:  # what the mixin reads of PhysicsWorld, the class it mixes into

        @property
        def dt(self) -> float: ...

        def ensure_built(self) -> None: ...

        def _slot(self, key: int) -> RagdollSlot: ...

        @property
        def commands(self) -> Commands: ...

    def _readback(self) -> tuple[_F, _F]:
        """Roots ``[P,3]`` and flat local rotations ``[ΣJ,4]`` of every ragdoll (cached per step)."""
        self.ensure_built()
        if self._read is None:
            assert self.layout is not None and self.data is not None
            self._read = read_poses(self.layout, self.data)
        return self._read

    def _outside(self, key: int) -> int | None:
        """The command row of a ragdoll left out of the model (it is exactly on its target), else ``None``."""
        self._slot(key)
        self.ensure_built()
        i = self.commands.row[key]
        return None if self.commands.in_model[i] else i

    def pose(self, key: int) -> Pose:
        """The ragdoll's simulated pose as an engine :class:`Pose` (root + local rotations)."""
        if (out := self._outside(key)) is not None:
            root, rot = self.commands.pose(out)
            return Pose(root.copy(), rot.copy())
        roots, rot = self._readback()
        L = self.layout
        assert L is not None
        p = L.ordinal(key)
        return Pose(roots[p].copy(), rot[L.starts[p] : L.starts[p + 1]].copy())

    def simulated_state(self, keys: list[int]) -> tuple[_F, _F, _F, _F]:
        """:meth:`pose`, :meth:`root_velocity` and :meth:`kinetic_energy` of many ragdolls at once (the
        physics stage reads them for every simulated puppet after each step): roots ``[n,3]``, their
        local rotations end to end ``[ΣJ,4]``, root velocities ``[n,6]`` and energies ``[n]``. Each
        number is the one the single-ragdoll query gives."""
        C = self.commands
        self.ensure_built()
        rows = C.rows(keys)
        n = len(keys)
        roots, vel, ke = np.empty((n, 3)), np.empty((n, 6)), np.empty(n)
        rot = np.empty((int(C.joints[rows].sum()), 4))
        ends = np.cumsum(C.joints[rows])
        inside = np.nonzero(C.in_model[rows])[0]
        L, d = self.layout, self.data
        if len(inside):
            assert L is not None and d is not None
            all_roots, all_rot = self._readback()
            ordinal = np.searchsorted(np.asarray(L.keys, dtype=np.int64), C.keys[rows[inside]])
            roots[inside] = all_roots[ordinal]
            rot[joint_rows(np.concatenate([[0], ends]), inside)] = all_rot[joint_rows(L.starts, ordinal)]
            vel[inside] = d.qvel[L.root_d[ordinal][:, None] + np.arange(6)]
            ke[inside] = self._energies()[ordinal]
        for k in np.nonzero(~C.in_model[rows])[0].tolist():  # left out (a full pool): from their commands
            key = int(keys[k])
            pose = self.pose(key)
            roots[k], rot[ends[k] - len(pose.rotations) : ends[k]] = pose.root, pose.rotations
            vel[k], ke[k] = self.root_velocity(key), 0.0
        return roots, rot, vel, ke

    def body_positions(self, key: int) -> _F:
        """World positions ``[J,3]`` of the ragdoll's joint origins."""
        if (out := self._outside(key)) is not None:
            spec = self._slot(key).spec
            root, rot = self.commands.pose(out)
            return forward_kinematics(spec.skeleton, root, rot, spec.offsets)[0]
        L, d = self.layout, self.data
        assert L is not None and d is not None
        return d.xpos[L.body[L.body_owner == L.ordinal(key)]].copy()

    def root_velocity(self, key: int) -> _F:
        """The root's free-joint velocity ``[6]`` (linear world, angular local)."""
        if (out := self._outside(key)) is not None:  # its target's velocity over the last step
            v, last, prev = np.zeros(6), self.commands.last(out), self.commands.prev(out)
            if last is not None and prev is not None:
                v[:3] = (last[0] - prev[0]) / self.dt
                v[3:] = quat.log(quat.mul(quat.conjugate(prev[1][0]), last[1][0])) / self.dt
            return v
        L, d = self.layout, self.data
        assert L is not None and d is not None
        rd = int(L.root_d[L.ordinal(key)])
        return d.qvel[rd : rd + 6].copy()

    def kinetic_energy(self, key: int) -> float:
        """Kinetic energy (J) of one ragdoll, ½ vᵀMv over its own degrees of freedom (0 for an
        animated ragdoll left out of the model: nothing is simulated)."""
        if self._outside(key) is not None:
            return 0.0
        assert self.layout is not None
        return float(self._energies()[self.layout.ordinal(key)])

    def _energies(self) -> _F:
        """Kinetic energy of every ragdoll in the layout (cached per step)."""
        L, m, d = self.layout, self.model, self.data
        assert L is not None and m is not None and d is not None
        if self._ke is None:
            res = np.zeros(m.nv)
            mujoco.mj_mulM(m, d, res, d.qvel)
            cum = np.concatenate([[0.0], np.cumsum(0.5 * d.qvel * res)])
            self._ke = cum[L.dofs[:, 1]] - cum[L.dofs[:, 0]]
        return self._ke

    def joint_limit_violation(self, key: int) -> float:
        """Largest excess (rad) of any simulated joint beyond its cone, twist or hinge range (0 when
        within, and for an animated ragdoll left out of the model)."""
        if self._outside(key) is not None:
            return 0.0
        roots, rot = self._readback()
        L, d = self.layout, self.data
        assert L is not None and d is not None
        p = L.ordinal(key)
        b, h = L.ball_owner == p, L.hinge_owner == p
        q = rot[L.ball_src[b]]
        cone = np.max(quat.angle_between(quat.identity(len(q)), q) - L.ball_cone[b], initial=0.0)
        _, tw = quat.swing_twist(quat.align_hemisphere(q), L.ball_axis[b])
        tang = np.abs(2.0 * np.arctan2(np.sum(tw[:, 1:] * L.ball_axis[b], axis=1), tw[:, 0]))
        twist = np.max(tang - L.ball_twist[b], initial=0.0)
        a = d.qpos[L.hinge_q[h]]
        hinge = np.max(np.maximum(L.hinge_range[h, 0] - a, a - L.hinge_range[h, 1]), initial=0.0)
        return float(max(cone, twist, hinge, 0.0))
