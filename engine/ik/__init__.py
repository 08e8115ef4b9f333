"""Inverse kinematics: analytic two-bone limbs and the optimisation IK of thesis §4.2.5.

- :func:`two_bone_ik` — law-of-cosines limb solver with a pole, batched, per frame.
- :func:`solve_ik` — any joint as effector, pins within ε, joint limits and
  stiffness, one QP (engine.qp) per linearisation (Eq. 4.13), rejection of
  unreachable targets after five non-improving iterations (§4.2.3).
- :func:`ground_feet` / :func:`hands_on_sphere` — feet on uneven ground, palms on a
  snowball, both through the two-bone solver.
- :class:`IKRequest` + :func:`ik_system` + :func:`install_ik` — the ``ik`` stage.
"""

from engine.ik.grounding import HUMANOID_LEGS, HeightfieldGround, Leg, PlaneGround, ground_feet
from engine.ik.hands import HUMANOID_ARMS, Arm, hands_on_sphere, sphere_contacts
from engine.ik.rig import BALL, FIXED, HINGE, IKRig, humanoid_rig
from engine.ik.solver import Effector, IKResult, IKSettings, Pin, solve_ik
from engine.ik.system import IKGround, IKRequest, IKRigCache, ik_system, install_ik
from engine.ik.two_bone import two_bone_ik

__all__ = [
    "two_bone_ik",
    "IKRig",
    "humanoid_rig",
    "BALL",
    "HINGE",
    "FIXED",
    "Effector",
    "Pin",
    "IKSettings",
    "IKResult",
    "solve_ik",
    "PlaneGround",
    "HeightfieldGround",
    "Leg",
    "HUMANOID_LEGS",
    "ground_feet",
    "Arm",
    "HUMANOID_ARMS",
    "sphere_contacts",
    "hands_on_sphere",
    "IKRequest",
    "IKGround",
    "IKRigCache",
    "ik_system",
    "install_ik",
]
