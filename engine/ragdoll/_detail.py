"""The physics step's level of detail: a crowd in the model steps in fewer, longer substeps.

MuJoCo's cost per simulation step is its cost per substep times the substeps, and the cost per
substep grows with every ragdoll in the model (contacts, limits, islands). One puppet, or a few,
costs little at the fine resolution (``PhysicsWorld.substeps``, 8 at 60 Hz), which the
single-puppet scenes keep; ten puppets falling in a crowd of a hundred hold some twenty ragdolls
in the model, whose eight substeps alone overran the 60 Hz frame. From :data:`CROWD` ragdolls in
the model a step is taken in ``crowd_substeps`` (4): half the MuJoCo work.

Longer substeps need one change to stay stable: a limp hand (0.5 kg, 4e-4 kg m²) pinched between
its own arm and head, or between two fallen puppets, was thrown at over 10x the velocity bound
inside one 1/240 s substep (a recovery; seeds 1 and 3 of the crowd-fall bench). Its wrist's
armature was 1.4e-4 kg m²; at the coarse resolution every ball and hinge joint has at least
:data:`ARMATURE` (rotor inertia, about the hand's own inertia about its wrist), which slows what a
contact impulse can do to a light limb within one substep and leaves heavy limbs as they were. No
recovery in 2.5 s after ten of a hundred fall (seeds 1-3), where the fine resolution had seven.

Which resolution a step takes depends only on how many ragdolls the model holds, which is part
of the simulation state: replays take the same one.
"""

from __future__ import annotations

import mujoco
import numpy as np
from numpy.typing import NDArray

from engine.arrays import F64 as _F
from engine.ragdoll._layout import Layout

__all__ = ["ARMATURE", "CROWD", "WALKER", "Detail"]

CROWD = 8  # ragdolls in the model from which a step is taken at the crowd resolution
ARMATURE = 0.002  # kg m²: least armature of a ragdoll's ball or hinge joint at the crowd resolution
WALKER = 0.05  # kg m²: least armature of an animated ragdoll's joints there (see below)


class Detail:
    """The resolution one model steps at, switched in place (timestep and armature are model fields).

    Args:
        substeps: the fine resolution (the physics world's ``substeps``).
        crowd_substeps: the crowd's (no switch when it is not fewer).
        dt: seconds per simulation step.
    """

    def __init__(self, substeps: int, crowd_substeps: int, dt: float) -> None:
        self.substeps, self.crowd_substeps, self.dt = substeps, crowd_substeps, dt
        self.coarse = False
        self._timestep = (dt / substeps, dt / crowd_substeps)
        self._armature: tuple[_F, _F] = (np.zeros(0), np.zeros(0))

    def compiled(self, m: mujoco.MjModel) -> None:
        """A new model (at the fine resolution, as compiled): remember both armatures of its joints."""
        self.coarse = False
        self._timestep = (float(m.opt.timestep), self._timestep[1])  # the compiled one, bit for bit
        fine = m.dof_armature.copy()
        kind = m.jnt_type[m.dof_jntid]
        joint = (kind == int(mujoco.mjtJoint.mjJNT_BALL)) | (kind == int(mujoco.mjtJoint.mjJNT_HINGE))
        self._armature = (fine, np.where(joint, np.maximum(fine, ARMATURE), fine))

    @property
    def current(self) -> int:
        """The substeps the model is set to now."""
        return self.crowd_substeps if self.coarse else self.substeps

    def substeps_for(self, m: mujoco.MjModel, L: Layout, kinematic: NDArray[np.bool_]) -> int:
        """Set the model to the resolution for the ragdolls of layout ``L`` (``kinematic [P]``: which
        are animated); the substeps to take."""
        coarse = self.crowd_substeps < self.substeps and L.num_ragdolls >= CROWD
        if coarse != self.coarse:
            self.coarse = coarse
            m.opt.timestep = self._timestep[int(coarse)]
            m.dof_armature[:] = self._armature[int(coarse)]
        if coarse:  # an animated ragdoll's joints take what it touches almost without giving way
            walker = np.concatenate(
                [L.ball_d[kinematic[L.ball_owner], None] + np.arange(3), L.hinge_d[kinematic[L.hinge_owner], None]],
                axis=None,
            )
            m.dof_armature[:] = self._armature[1]
            m.dof_armature[walker] = np.maximum(self._armature[1][walker], WALKER)
        return self.current
