"""A rigged glTF humanoid as a puppet skeleton: the puppet's 17 roles with the character's proportions.

Everything that makes a puppet live (the state machine, the blend space, the leg IK, the
ragdoll's hinge axes) is written for the puppet's hierarchy and its rest convention: with
every local rotation the identity, the figure stands facing +Z, arms hanging, legs straight.
A character keeps that convention and brings its own sizes:

- **Torso** (hips, spine, chest, neck, head) and the **limb roots** (where the arms and legs
  hang from) sit where the file puts them in its rest pose, so the hips are as wide and the
  shoulders as high as the mesh says.
- **Limb bones** (upper/lower arm and leg) keep the puppet's directions with the character's
  lengths: a T-posed or A-posed arm becomes a hanging one of the same length.

:attr:`CharacterRig.rest_local` is the pose that puts this skeleton back into the file's own
rest pose (the limbs turned up into the T or A), so the skin can be bound there
(:mod:`engine.character.binding`) and every clip made for the puppet drives the mesh.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from engine import quat
from engine.arrays import F64
from engine.fk import forward_kinematics
from engine.humanoid import JOINTS, humanoid_skeleton
from engine.skeleton import Skeleton

__all__ = ["CharacterRig", "build_rig", "LIMB_BONES", "RigError"]


#: Joints whose bone (towards their child) keeps the puppet's rest direction.
LIMB_BONES = (
    "l_upper_arm",
    "l_lower_arm",
    "r_upper_arm",
    "r_lower_arm",
    "l_upper_leg",
    "l_lower_leg",
    "r_upper_leg",
    "r_lower_leg",
)


class RigError(ValueError):
    """A character whose rest pose the puppet cannot stand in (lying down, left and right swapped…)."""


@dataclass(frozen=True)
class CharacterRig:
    """The puppet skeleton of a character and how it sits in the file.

    Attributes:
        skeleton: the puppet's joints (:data:`engine.humanoid.JOINTS`) with the character's
            offsets, tips and radii; standing on y = 0, hips over the origin, facing +Z.
        rest_local: ``[17,4]`` local rotations of the file's rest pose (joint 0's: identity).
        to_engine: ``[4,4]`` the file's world (glTF scene) into the engine's: a turn about +Y
            (a character facing -Z is turned round) and a move putting the soles on y = 0.
        rest_positions: ``[17,3]`` the roles' joints in the file's rest, in engine space.
    """

    skeleton: Skeleton
    rest_local: F64
    to_engine: F64
    rest_positions: F64


def _unit(v: F64) -> F64:
    return v / max(float(np.linalg.norm(v)), 1e-12)


def _facing(p: dict[str, F64]) -> F64:
    """``[3,3]`` turn about +Y making the character face +Z with its left at +X (the puppet's convention)."""
    left = p["l_upper_leg"] - p["r_upper_leg"]
    left[1] = 0.0
    if np.linalg.norm(left) < 1e-9:
        raise RigError("the legs hang from one point: left and right cannot be told apart")
    x = _unit(left)
    z = np.cross(x, [0.0, 1.0, 0.0])
    return np.stack([x, [0.0, 1.0, 0.0], z])  # rows: where the file's axes go; applied as m @ v


def build_rig(
    positions: dict[str, F64],
    floor: float,
    sizes: dict[str, float] | None = None,
    radii: dict[str, float] | None = None,
) -> CharacterRig:
    """The puppet skeleton of a character from its roles' rest positions in the file.

    Args:
        positions: role → world position ``[3]`` in the file's rest pose (glTF scene, Y up,
            metres), for every one of the puppet's 17 roles.
        floor: height of the file's lowest vertex in that pose (where the soles stand).
        sizes: optional ``"head"`` (head joint to the top of the head), ``"hand"`` (wrist to
            fingertips), ``"toe"`` (ankle to the front of the foot), in metres.
        radii: role → capsule radius (from the mesh); the puppet's scaled by height otherwise.

    Raises:
        RigError: the rest pose does not stand up (hips not below the head), or a bone has no length.
    """
    missing = [r for r in JOINTS if r not in positions]
    if missing:
        raise RigError(f"roles without a joint: {', '.join(missing)}")
    base = humanoid_skeleton()
    if positions["head"][1] <= positions["hips"][1]:
        raise RigError("in its rest pose the head is not above the hips: the character does not stand Y up")
    turn = _facing({k: np.asarray(v, dtype=np.float64).copy() for k, v in positions.items()})
    hips = np.asarray(positions["hips"], dtype=np.float64)
    move = np.eye(4)
    move[:3, :3] = turn
    move[:3, 3] = -(turn @ np.array([hips[0], floor, hips[2]]))
    p = np.array([move[:3, :3] @ np.asarray(positions[n], dtype=np.float64) + move[:3, 3] for n in JOINTS])
    if p[0, 1] <= 0.0:
        raise RigError("the hips are not above the lowest vertex")
    scale = p[0, 1] / base.offsets[0, 1]  # hips height against the puppet's
    offsets = np.zeros((len(JOINTS), 3))
    world = quat.identity(len(JOINTS))
    offsets[0] = (0.0, p[0, 1], 0.0)
    for j in range(1, len(JOINTS)):
        parent = int(base.parents[j])
        bone = p[j] - p[parent]
        if np.linalg.norm(bone) < 1e-6:
            raise RigError(f"the bone to {JOINTS[parent]!r} from {JOINTS[j]!r} has no length")
        if JOINTS[parent] in LIMB_BONES:
            direction = _unit(base.offsets[j])
            offsets[j] = direction * np.linalg.norm(bone)
            world[parent] = quat.between(direction, bone)
        else:
            offsets[j] = bone
    for leaf, limb in (("l_hand", "l_lower_arm"), ("r_hand", "r_lower_arm")):
        world[JOINTS.index(leaf)] = world[JOINTS.index(limb)]  # a wrist continues its forearm
    local = np.array(world)
    for j in range(1, len(JOINTS)):
        local[j] = quat.mul(quat.conjugate(world[int(base.parents[j])]), world[j])
    tips = np.array(base.tips) * scale
    sizes = sizes or {}
    if sizes.get("head", 0.0) > 0.0:
        tips[JOINTS.index("head")] = (0.0, sizes["head"], 0.0)
    for side in ("l", "r"):
        if sizes.get("hand", 0.0) > 0.0:
            tips[JOINTS.index(f"{side}_hand")] = (0.0, -sizes["hand"], 0.0)
        foot = JOINTS.index(f"{side}_foot")
        toe = sizes.get("toe", float(base.tips[foot, 2]) * scale)
        tips[foot] = (0.0, -p[foot, 1], toe)  # the tip on the floor: retargeted clips plant it there
    r = np.array(base.radii) * scale
    for name, value in (radii or {}).items():
        r[JOINTS.index(name)] = value
    skeleton = Skeleton(JOINTS, base.parents, offsets, tips, r)
    fk, _ = forward_kinematics(skeleton, offsets[0], local)
    if not np.allclose(fk, p, atol=1e-6):
        raise RigError("internal: the rest pose does not reproduce the file's joints")
    return CharacterRig(skeleton, local, move, p)
