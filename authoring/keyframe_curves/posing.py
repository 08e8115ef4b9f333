"""Pose a key with the static IK (thesis §4.2.5, Eq. 4.13–4.14): drag any joint, pinned joints stay put.

The key's pose is the IK's input; the dragged joint is the effector; every joint held
(pinned or in contact) at the key's frame is a :class:`~engine.ik.Pin` within ε; the
humanoid rig brings the joint limits and the stiffness ``D`` (a stiff torso, soft limbs),
and the root may translate. A target the IK cannot reach is not thrown away: §4.4 keeps
the closest solution, so the key takes the closest pose found and the result says how far
it is from the target (the residual the editor shows).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike

from authoring.keyframe_curves.keys import pose_channels, set_key_channels
from engine.ik import Effector as _Effector
from engine.ik import IKRig, Pin, humanoid_rig, solve_ik
from engine.keyframes import KeyframedClip
from engine.skeleton import Skeleton

__all__ = ["KeyPose", "pose_key", "posing_rig", "ROOT_TRANSLATION_STIFFNESS"]

ROOT_TRANSLATION_STIFFNESS = 10.0  # per metre (D of Eq. 4.4 for the root's translation)


@dataclass(frozen=True)
class KeyPose:
    """What posing a key did: the clip, whether the target was met, the residual (metres) and the pins' drift."""

    clip: KeyframedClip
    reached: bool
    residual: float
    pin_error: float


_RIGS: dict[int, tuple[Skeleton, IKRig]] = {}


def posing_rig(skeleton: Skeleton) -> IKRig:
    """The rig keys are posed with: the humanoid's limits and stiffness where it applies, the root free to move."""
    cached = _RIGS.get(id(skeleton))
    if cached is not None and cached[0] is skeleton:
        return cached[1]
    try:
        rig = humanoid_rig(skeleton, root_translation=True)
    except (KeyError, ValueError):  # not the puppet's skeleton: all balls, ±π
        rig = IKRig.build(skeleton, root_translation=True)
    # The root's translation resists like the torso: 10 cm costs what a radian of a limb does,
    # so a foot or a hand is reached with its limb, not by sliding the whole puppet.
    stiffness = np.where(rig.dof_translation, ROOT_TRANSLATION_STIFFNESS, rig.stiffness)
    stiffness.setflags(write=False)
    rig = replace(rig, stiffness=stiffness)
    _RIGS[id(skeleton)] = (skeleton, rig)
    return rig


def pose_key(clip: KeyframedClip, k: int, joint: str | int, target: ArrayLike | None,
             pinned: tuple[str | int, ...] = (), orientation: ArrayLike | None = None) -> KeyPose:  # fmt: skip
    """Move ``joint`` of key ``k`` towards ``target`` (world) with ``pinned`` joints held; the closest pose is kept.

    Dragging the root (the hips) moves it without turning it, as an animator lowers the hips.
    With ``orientation`` (a world quaternion) the joint is turned too (or only, without ``target``).
    """
    sk = clip.skeleton
    n = clip.curves.times.size
    if not 0 <= k < n:
        raise ValueError(f"there is no key {k} (keys 0…{n - 1})")
    j = sk.index(joint) if isinstance(joint, str) else int(joint)
    old = clip.curves.values[k]
    root, rot = clip.pose_arrays(old[None])
    pins = tuple(Pin(p) for p in pinned if (sk.index(p) if isinstance(p, str) else int(p)) != j)
    # The root dragged translates the body: it keeps its orientation (else a lowered pelvis tips the torso over).
    keep = rot[0][0] if j == 0 and orientation is None else orientation
    res = solve_ik(posing_rig(sk), root[0], rot[0], [_Effector(j, position=target, orientation=keep)], pins)
    channels = pose_channels(res.closest_root, res.closest_rotations, near=old)
    return KeyPose(set_key_channels(clip, k, channels), res.reached, res.error, res.pin_error)
