"""Ragdoll profiles: the immutable asset that says how a skeleton becomes rigid bodies.

A profile holds, per joint, the bone's capsule radius and mass, the joint kind
(``"free"`` for the root, ``"hinge"`` for knees and elbows, ``"ball"`` elsewhere), its
limits (hinge range; ball swing cone and twist range about the bone) and the muscle
bandwidth. :func:`default_profile` derives all of it from any :class:`Skeleton`: masses
follow capsule volume scaled to a total body mass, hinges are recognised by name, and
servo gains follow from each joint's subtree inertia so that every muscle has the same
natural frequency (a hand and a hip track equally fast, none is stiff enough to make
the 480 Hz step unstable).

Per-joint values are numpy arrays (structure of arrays), never per-joint objects.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from engine import quat
from engine.fk import forward_kinematics
from engine.skeleton import Skeleton

__all__ = ["RagdollProfile", "default_profile", "bone_segments", "servo_gains", "JOINT_KINDS"]

JOINT_KINDS = ("free", "ball", "hinge")
_DEG = np.pi / 180.0

# name fragment -> (kind, hinge axis, hinge range deg, cone deg, twist deg); first match wins.
_RULES: tuple[tuple[tuple[str, ...], str, tuple[float, float, float], tuple[float, float], float, float], ...] = (
    (("lower_leg", "knee", "shin", "calf", "leg_lower"), "hinge", (1, 0, 0), (-5, 150), 0, 0),
    (("lower_arm", "forearm", "elbow", "arm_lower"), "hinge", (1, 0, 0), (-150, 5), 0, 0),
    (("upper_leg", "thigh", "upleg", "hip_"), "ball", (1, 0, 0), (0, 0), 100, 35),
    (("upper_arm", "shoulder", "arm_upper"), "ball", (1, 0, 0), (0, 0), 150, 60),
    (("hand", "wrist"), "ball", (1, 0, 0), (0, 0), 60, 30),
    (("foot", "ankle", "toe"), "ball", (1, 0, 0), (0, 0), 45, 15),
    (("neck", "head"), "ball", (1, 0, 0), (0, 0), 45, 50),
    (("spine", "chest", "torso", "back"), "ball", (1, 0, 0), (0, 0), 35, 30),
)
_GENERIC = ("ball", (1.0, 0.0, 0.0), (0.0, 0.0), 60.0, 30.0)


@dataclass(frozen=True)
class RagdollProfile:
    """How each joint of a skeleton is simulated (an immutable asset, shared by puppets).

    Attributes:
        kinds: per joint ``"free"`` (root), ``"ball"`` or ``"hinge"``.
        radii: ``[J]`` capsule radius (m).
        masses: ``[J]`` body mass (kg).
        hinge_axis: ``[J,3]`` hinge axis in the joint frame (hinges only).
        hinge_range: ``[J,2]`` hinge limits (rad).
        cone: ``[J]`` ball swing limit (rad): MuJoCo limits the total rotation angle.
        twist: ``[J]`` ball twist limit about the bone (± rad), enforced by projection.
        frequency: muscle natural frequency (rad/s) at muscle weight 1.
        leaf_boost: frequency factor for leaf joints (hands, feet, head): they carry almost no
            inertia, so a faster muscle costs nothing and keeps fast toe-offs tracked.
        damping_ratio: muscle damping ratio (1 = critical).
        joint_damping: passive joint damping as a share of each joint's full muscle damping, so
            limp bodies stay calm and a hand is damped as much as a hip, relative to its inertia.
        holdable: joints a MotionStick may hold by a spring (item 4 of the issue).
        friction: sliding friction of the body capsules.
    """

    kinds: tuple[str, ...]
    radii: NDArray[np.float64]
    masses: NDArray[np.float64]
    hinge_axis: NDArray[np.float64]
    hinge_range: NDArray[np.float64]
    cone: NDArray[np.float64]
    twist: NDArray[np.float64]
    frequency: float = 30.0
    leaf_boost: float = 2.0
    damping_ratio: float = 1.0
    joint_damping: float = 0.05
    holdable: tuple[str, ...] = ()
    friction: float = 0.9

    def __post_init__(self) -> None:
        n = len(self.kinds)
        if n == 0 or self.kinds[0] != "free" or any(k not in JOINT_KINDS[1:] for k in self.kinds[1:]):
            raise ValueError("profile kinds: joint 0 must be 'free', the others 'ball' or 'hinge'")
        shapes = {
            "radii": (n,),
            "masses": (n,),
            "hinge_axis": (n, 3),
            "hinge_range": (n, 2),
            "cone": (n,),
            "twist": (n,),
        }
        for name, shape in shapes.items():
            value = np.array(getattr(self, name), dtype=np.float64).reshape(shape)
            value.setflags(write=False)
            object.__setattr__(self, name, value)
        if np.any(self.radii <= 0) or np.any(self.masses <= 0):
            raise ValueError("profile radii and masses must be positive")
        if np.any(self.hinge_range[:, 0] > self.hinge_range[:, 1]):
            raise ValueError("hinge_range: lower limit above upper limit")
        if self.frequency <= 0 or self.damping_ratio < 0:
            raise ValueError("frequency must be positive and damping_ratio non-negative")

    @property
    def num_joints(self) -> int:
        """Number of joints ``J``."""
        return len(self.kinds)

    def with_masses(self, masses: ArrayLike) -> RagdollProfile:
        """The same profile with other per-joint masses."""
        return replace(self, masses=np.asarray(masses, dtype=np.float64))

    def with_radii(self, radii: ArrayLike) -> RagdollProfile:
        """The same profile with other per-joint capsule radii."""
        return replace(self, radii=np.asarray(radii, dtype=np.float64))


def _rule(name: str) -> tuple[str, tuple[float, float, float], tuple[float, float], float, float]:
    low = name.lower()
    for keys, kind, axis, rng, cone, twist in _RULES:
        if any(k in low for k in keys):
            return kind, axis, rng, cone, twist
    return _GENERIC


def bone_segments(
    skeleton: Skeleton, radii: ArrayLike, offsets: ArrayLike | None = None
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Capsule segment ``(p0 [J,3], p1 [J,3], radius [J])`` of every bone in its joint's frame.

    The bone runs from the joint to its first child (or its tip for a leaf). The segment is
    shortened by the radius at both ends so the capsule's caps end exactly at the joint and
    at the bone's end (a foot capsule touches the ground where the foot tip does). A bone
    shorter than its diameter becomes a sphere at its midpoint (``p0 == p1``).
    """
    r = np.asarray(radii, dtype=np.float64)
    off = skeleton.offsets if offsets is None else np.asarray(offsets, dtype=np.float64)
    ends = np.array(skeleton.tips, dtype=np.float64)
    for j in range(skeleton.num_joints):
        kids = skeleton.children(j)
        if kids:
            ends[j] = off[kids[0]]
    length = np.linalg.norm(ends, axis=1)
    u = ends / np.where(length > 1e-9, length, 1.0)[:, None]
    sphere = length <= 2.0 * r
    p0 = np.where(sphere[:, None], 0.5 * ends, r[:, None] * u)
    p1 = np.where(sphere[:, None], 0.5 * ends, ends - r[:, None] * u)
    return p0, p1, r.copy()


def _capsule_volume(p0: NDArray[np.float64], p1: NDArray[np.float64], r: NDArray[np.float64]) -> NDArray[np.float64]:
    return np.pi * r**2 * np.linalg.norm(p1 - p0, axis=1) + 4.0 / 3.0 * np.pi * r**3


def default_profile(
    skeleton: Skeleton,
    total_mass: float = 70.0,
    radii: ArrayLike | None = None,
    masses: ArrayLike | None = None,
    offsets: ArrayLike | None = None,
    frequency: float = 30.0,
    holdable: tuple[str, ...] | None = None,
) -> RagdollProfile:
    """A profile for any skeleton: capsule sizes from the bones, limits from joint names.

    Args:
        skeleton: the hierarchy.
        total_mass: body mass spread over the bones by capsule volume (ignored with ``masses``).
        radii: per-joint capsule radii; defaults to ``skeleton.radii``.
        masses: per-joint masses; defaults to the volume share of ``total_mass``.
        offsets: per-puppet bone offsets (snowmen) used to size the capsules.
        frequency: muscle natural frequency in rad/s.
        holdable: joints the MotionStick may hold; defaults to ``chest`` and ``head`` where present
            (else the root).
    """
    n = skeleton.num_joints
    r = np.asarray(skeleton.radii if radii is None else radii, dtype=np.float64).reshape(n)
    kinds, axes, ranges, cones, twists = ["free"], [(1.0, 0.0, 0.0)], [(0.0, 0.0)], [0.0], [0.0]
    for name in skeleton.names[1:]:
        kind, axis, rng, cone, twist = _rule(name)
        kinds.append(kind)
        axes.append(axis)
        ranges.append((rng[0] * _DEG, rng[1] * _DEG))
        cones.append(cone * _DEG)
        twists.append(twist * _DEG)
    if masses is None:
        vol = _capsule_volume(*bone_segments(skeleton, r, offsets))
        m = total_mass * vol / vol.sum()
    else:
        m = np.asarray(masses, dtype=np.float64)
    if holdable is None:
        holdable = tuple(h for h in ("chest", "head") if h in skeleton.names) or (skeleton.names[0],)
    for h in holdable:
        skeleton.index(h)
    return RagdollProfile(
        tuple(kinds),
        r,
        m,
        np.array(axes),
        np.array(ranges),
        np.array(cones),
        np.array(twists),
        frequency=frequency,
        holdable=tuple(holdable),
    )


def servo_gains(
    skeleton: Skeleton, profile: RagdollProfile, offsets: ArrayLike | None = None
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Muscle gains ``(kp [J], kv [J])`` giving every joint the profile's natural frequency.

    ``kp = ω² I`` and ``kv = 2 ζ ω I``, where ``I`` is the rest-pose inertia of the joint's
    whole subtree about the joint (point masses at capsule centres plus each capsule's own
    spread) and ``ω`` the profile's frequency (times ``leaf_boost`` for leaves). The root
    has no muscle (its entry is 0): the pin holds it.
    """
    off = skeleton.offsets if offsets is None else np.asarray(offsets, dtype=np.float64)
    p0, p1, r = bone_segments(skeleton, profile.radii, off)
    wpos, wrot = forward_kinematics(skeleton, off[0], quat.identity(skeleton.num_joints), off)
    centres = wpos + quat.rotate(wrot, 0.5 * (p0 + p1))
    own = profile.masses * (r**2 / 2.0 + np.sum((p1 - p0) ** 2, axis=1) / 12.0)
    inertia = np.zeros(skeleton.num_joints)
    for j in range(1, skeleton.num_joints):
        sub = [j]
        for k in range(j + 1, skeleton.num_joints):
            if skeleton.parents[k] in sub:
                sub.append(k)
        d2 = np.sum((centres[sub] - wpos[j]) ** 2, axis=1)
        inertia[j] = float(np.sum(profile.masses[sub] * d2 + own[sub]))
    leaf = np.ones(skeleton.num_joints, dtype=bool)
    leaf[skeleton.parents[1:]] = False
    w = profile.frequency * np.where(leaf, profile.leaf_boost, 1.0)
    return w * w * inertia, 2.0 * profile.damping_ratio * w * inertia
