"""The default puppet's skeleton: a 17-joint humanoid, 1.7 m tall, facing +Z, Y up.

The rest pose is a relaxed stand with the arms hanging, so an identity rotation is
a natural pose; the character's left is +X. Bone radii give the renderer and the
ragdoll their capsule thickness.
"""

from __future__ import annotations

import numpy as np

from engine.skeleton import Skeleton

__all__ = ["humanoid_skeleton", "JOINTS", "HIP_HEIGHT"]

HIP_HEIGHT = 0.95

# name, parent, offset from parent, tip (leaves only), radius
_SPEC: tuple[tuple[str, str | None, tuple[float, float, float], tuple[float, float, float], float], ...] = (
    ("hips", None, (0.0, HIP_HEIGHT, 0.0), (0, 0, 0), 0.095),
    ("spine", "hips", (0.0, 0.10, 0.0), (0, 0, 0), 0.11),
    ("chest", "spine", (0.0, 0.18, 0.0), (0, 0, 0), 0.085),
    ("neck", "chest", (0.0, 0.22, 0.0), (0, 0, 0), 0.05),
    ("head", "neck", (0.0, 0.10, 0.0), (0.0, 0.20, 0.0), 0.10),
    ("l_upper_arm", "chest", (0.17, 0.17, 0.0), (0, 0, 0), 0.05),
    ("l_lower_arm", "l_upper_arm", (0.0, -0.28, 0.0), (0, 0, 0), 0.04),
    ("l_hand", "l_lower_arm", (0.0, -0.25, 0.0), (0.0, -0.09, 0.0), 0.04),
    ("r_upper_arm", "chest", (-0.17, 0.17, 0.0), (0, 0, 0), 0.05),
    ("r_lower_arm", "r_upper_arm", (0.0, -0.28, 0.0), (0, 0, 0), 0.04),
    ("r_hand", "r_lower_arm", (0.0, -0.25, 0.0), (0.0, -0.09, 0.0), 0.04),
    ("l_upper_leg", "hips", (0.09, -0.05, 0.0), (0, 0, 0), 0.07),
    ("l_lower_leg", "l_upper_leg", (0.0, -0.42, 0.0), (0, 0, 0), 0.055),
    ("l_foot", "l_lower_leg", (0.0, -0.42, 0.0), (0.0, -0.05, 0.15), 0.045),
    ("r_upper_leg", "hips", (-0.09, -0.05, 0.0), (0, 0, 0), 0.07),
    ("r_lower_leg", "r_upper_leg", (0.0, -0.42, 0.0), (0, 0, 0), 0.055),
    ("r_foot", "r_lower_leg", (0.0, -0.42, 0.0), (0.0, -0.05, 0.15), 0.045),
)

JOINTS: tuple[str, ...] = tuple(s[0] for s in _SPEC)


def humanoid_skeleton() -> Skeleton:
    """A fresh copy of the default puppet's skeleton."""
    names = [s[0] for s in _SPEC]
    parents = [-1 if s[1] is None else names.index(s[1]) for s in _SPEC]
    return Skeleton(
        tuple(names),
        np.array(parents),
        np.array([s[2] for s in _SPEC], dtype=np.float64),
        np.array([s[3] for s in _SPEC], dtype=np.float64),
        np.array([s[4] for s in _SPEC], dtype=np.float64),
    )
