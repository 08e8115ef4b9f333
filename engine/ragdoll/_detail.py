"""The physics step's level of detail: a crowd in the model steps in fewer, longer substeps.

MuJoCo's cost per simulation step is its cost per substep times the substeps, and the cost per
substep grows with every ragdoll in the model (contacts, limits, islands). One puppet, or a few,
costs little at the fine resolution (``PhysicsWorld.substeps``, 8 at 60 Hz), which the
single-puppet scenes keep; ten puppets falling in a crowd of a hundred hold some twenty ragdolls
in the model, whose eight substeps alone overran the 60 Hz frame. From :data:`CROWD` ragdolls in
the model a step is taken in ``crowd_substeps`` (5): five eighths of the MuJoCo work.

Longer substeps need one change to stay stable: a limp hand (0.5 kg, 4e-4 kg m²) pinched between
its own arm and head, or between two fallen puppets, was thrown at over 10x the velocity bound
inside one 1/240 s substep at 4 substeps (a recovery, the step undone; seeds 1 and 3 of the
crowd-fall bench).
Its wrist's armature (rotor inertia) was 1.4e-4 kg m², a foot's 1e-3; at the crowd resolution every
ball and hinge joint has at least :data:`ARMATURE`, about twice a hand's inertia about its wrist, which
slows what a contact impulse does to a light limb within one substep and leaves the heavy limbs
(hips, spine: 0.1-0.2) as they were. Measured over 2.5 s after ten of a hundred go limp, at 4
substeps: 0.002 left one recovery in seeds 1-3, 0.005 none there but ten in seeds 4-6; making only
the animated neighbours' joints heavy (0.05, so they barely give way) was worse (a walker that does
not yield drove a limb 0.3 m into the ground). At 5 substeps with 0.005: none in seeds 1-6, where the
8 substeps of before had seven in seed 3 and one each in seeds 4 and 5.

Which resolution a step takes depends only on how many ragdolls the model holds, which is part
of the simulation state: replays take the same one.
"""

from __future__ import annotations

import mujoco
import numpy as np

from engine.arrays import F64 as _F

__all__ = ["ARMATURE", "CROWD", "Detail"]

CROWD = 8  # ragdolls in the model from which a step is taken at the crowd resolution
ARMATURE = 0.005  # kg m²: least armature of a ragdoll's ball or hinge joint at the crowd resolution


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

    def substeps_for(self, m: mujoco.MjModel, ragdolls: int) -> int:
        """Set the model to the resolution for ``ragdolls`` in it; the substeps to take."""
        coarse = self.crowd_substeps < self.substeps and ragdolls >= CROWD
        if coarse != self.coarse:
            self.coarse = coarse
            m.opt.timestep = self._timestep[int(coarse)]
            m.dof_armature[:] = self._armature[int(coarse)]
        return self.current
