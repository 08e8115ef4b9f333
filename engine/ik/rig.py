"""The IK rig: which joints move, how (ball, hinge, fixed), their limits and stiffness.

The optimisation IK (thesis §4.2.5) works on *attributes* ``c``, not on quaternions:
each ball joint contributes three coordinates, the rotation vector of its local
rotation (``q = exp(c)``); a hinge contributes one angle about a local axis on top of
whatever swing the input pose had (``q = swing · exp(c·axis)``); a fixed joint
contributes none. The root may add three translation coordinates. Limits
``u_i ≤ c_i ≤ v_i`` and the stiffness ``D`` of Eq. 4.13 are per coordinate, so they
are plain ``[K]`` arrays here, and converting between a pose and ``c`` is a couple of
vectorised quaternion calls — no per-joint objects.

Why rotation vectors: they are a chart of SO(3) around the rest pose, so per-component
box limits read as "this much bend about X, this much twist about Y", and with the
right Jacobian of SO(3) (see :mod:`engine.ik.jacobian`) their derivatives are exact.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from engine import quat
from engine.arrays import F64 as F
from engine.skeleton import Skeleton

__all__ = ["IKRig", "FIXED", "HINGE", "BALL", "humanoid_rig"]

FIXED, HINGE, BALL = 0, 1, 3


@dataclass(frozen=True)
class IKRig:
    """The per-coordinate layout of a skeleton for the optimisation IK (an immutable asset).

    Attributes:
        skeleton: the hierarchy.
        kinds: ``[J]`` FIXED, HINGE or BALL per joint.
        axes: ``[J,3]`` unit hinge axis in the joint's local frame (unused for others).
        lower, upper: ``[K]`` limits per coordinate (radians; metres for root translation).
        stiffness: ``[K]`` diagonal of ``D`` (resistance to change, Eq. 4.4).
        dof_joint: ``[K]`` the joint each coordinate belongs to.
        dof_slot: ``[K]`` component within the joint (0..2 for a ball, 0 for a hinge).
        dof_translation: ``[K]`` True for the root's translation coordinates.
        ancestors: ``[J,J]`` ``ancestors[f, j]`` is True when ``j`` is ``f`` or above it.
    """

    skeleton: Skeleton
    kinds: NDArray[np.int64]
    axes: F
    lower: F
    upper: F
    stiffness: F
    dof_joint: NDArray[np.int64]
    dof_slot: NDArray[np.int64]
    dof_translation: NDArray[np.bool_]
    ancestors: NDArray[np.bool_]

    @classmethod
    def build(
        cls,
        skeleton: Skeleton,
        *,
        hinges: Mapping[str, ArrayLike] | None = None,
        fixed: tuple[str, ...] = (),
        limits: Mapping[str, tuple[ArrayLike, ArrayLike]] | None = None,
        stiffness: Mapping[str, ArrayLike] | None = None,
        root_translation: bool = False,
        default_limit: float = np.pi,
        translation_limit: float = 10.0,
    ) -> IKRig:
        """A rig where every joint is a ball unless named in ``hinges`` (name → local axis) or ``fixed``.

        ``limits`` maps a joint name to ``(lower, upper)`` (3 values for a ball, 1 for a
        hinge, or scalars broadcast); ``stiffness`` maps a name to a scalar or per-coordinate
        values (default 1). Unknown names raise ``KeyError`` naming the joints.
        """
        hinges = dict(hinges or {})
        limits = dict(limits or {})
        stiffness = dict(stiffness or {})
        for name in (*hinges, *fixed, *limits, *stiffness):
            skeleton.index(name)
        n = skeleton.num_joints
        kinds = np.full(n, BALL, dtype=np.int64)
        axes = np.zeros((n, 3))
        for name, axis in hinges.items():
            a = np.asarray(axis, dtype=np.float64).reshape(3)
            if np.linalg.norm(a) < 1e-9:
                raise ValueError(f"hinge {name!r} needs a non-zero axis")
            kinds[skeleton.index(name)] = HINGE
            axes[skeleton.index(name)] = a / np.linalg.norm(a)
        for name in fixed:
            kinds[skeleton.index(name)] = FIXED
        dof_joint, dof_slot, dof_trans, lo, hi, st = [], [], [], [], [], []
        if root_translation:
            for s in range(3):
                dof_joint.append(0)
                dof_slot.append(s)
                dof_trans.append(True)
                lo.append(-translation_limit)
                hi.append(translation_limit)
                st.append(1.0)
        for j in range(n):
            k = int(kinds[j])
            if k == FIXED:
                continue
            name = skeleton.names[j]
            jl, ju = limits.get(name, (-default_limit, default_limit))
            jl = np.broadcast_to(np.asarray(jl, dtype=np.float64), (k,))
            ju = np.broadcast_to(np.asarray(ju, dtype=np.float64), (k,))
            if np.any(jl > ju):
                raise ValueError(f"joint {name!r}: lower limit above upper limit")
            js = np.broadcast_to(np.asarray(stiffness.get(name, 1.0), dtype=np.float64), (k,))
            if np.any(js < 0):
                raise ValueError(f"joint {name!r}: stiffness must be non-negative")
            for s in range(k):
                dof_joint.append(j)
                dof_slot.append(s)
                dof_trans.append(False)
                lo.append(jl[s])
                hi.append(ju[s])
                st.append(js[s])
        anc = np.zeros((n, n), dtype=bool)
        for j in range(n):
            anc[j, j] = True
            if skeleton.parents[j] >= 0:
                anc[j] |= anc[skeleton.parents[j]]
        arrays = {
            "kinds": kinds,
            "axes": axes,
            "lower": np.array(lo),
            "upper": np.array(hi),
            "stiffness": np.array(st),
            "dof_joint": np.array(dof_joint, dtype=np.int64),
            "dof_slot": np.array(dof_slot, dtype=np.int64),
            "dof_translation": np.array(dof_trans, dtype=bool),
            "ancestors": anc,
        }
        for a in arrays.values():
            a.setflags(write=False)
        return cls(skeleton=skeleton, **arrays)

    @property
    def num_dofs(self) -> int:
        """Number of coordinates ``K``."""
        return int(self.dof_joint.shape[0])

    def to_coordinates(self, root: ArrayLike, rotations: ArrayLike) -> tuple[F, F]:
        """``(c [K], pre [J,4])`` for a pose: coordinates, and the fixed part of each rotation.

        ``pre`` is the identity for ball joints, the swing for hinges, and the whole
        rotation for fixed joints, so that :meth:`to_pose` rebuilds the input exactly.
        """
        rot = quat.align_hemisphere(quat.normalize(np.asarray(rotations, dtype=np.float64)))
        root = np.asarray(root, dtype=np.float64)
        rvec = quat.log(rot)
        pre = quat.identity(self.skeleton.num_joints)
        hinge = self.kinds == HINGE
        twist_angle = 2.0 * np.arctan2(np.sum(rot[:, 1:] * self.axes, axis=-1), rot[:, 0])
        twist = quat.from_axis_angle(self.axes, twist_angle)
        pre[hinge] = quat.mul(rot[hinge], quat.conjugate(twist[hinge]))
        pre[self.kinds == FIXED] = rot[self.kinds == FIXED]
        c = np.empty(self.num_dofs)
        t = self.dof_translation
        c[t] = root[self.dof_slot[t]]
        r = ~t
        ball = self.kinds[self.dof_joint[r]] == BALL
        c[r] = np.where(ball, rvec[self.dof_joint[r], self.dof_slot[r]], twist_angle[self.dof_joint[r]])
        return c, pre

    def rotation_vectors(self, c: ArrayLike) -> F:
        """``[J,3]`` local rotation vectors of the coordinates (zero for fixed joints)."""
        c = np.asarray(c, dtype=np.float64)
        rv = np.zeros((self.skeleton.num_joints, 3))
        r = ~self.dof_translation
        j, s = self.dof_joint[r], self.dof_slot[r]
        ball = self.kinds[j] == BALL
        rv[j[ball], s[ball]] = c[r][ball]
        hj = j[~ball]
        rv[hj] = self.axes[hj] * c[r][~ball][:, None]
        return rv

    def to_pose(self, c: ArrayLike, pre: ArrayLike, root: ArrayLike) -> tuple[F, F]:
        """``(root [3], rotations [J,4])`` of coordinates ``c`` (``root`` is used where not a coordinate)."""
        c = np.asarray(c, dtype=np.float64)
        out_root = np.array(root, dtype=np.float64)
        t = self.dof_translation
        out_root[self.dof_slot[t]] = c[t]
        return out_root, quat.mul(pre, quat.exp(self.rotation_vectors(c)))

    def within_limits(self, c: ArrayLike, tol: float = 1e-9) -> bool:
        """True when every coordinate lies in its limits."""
        c = np.asarray(c)
        return bool(np.all(c >= self.lower - tol) and np.all(c <= self.upper + tol))


def humanoid_rig(skeleton: Skeleton, *, root_translation: bool = False) -> IKRig:
    """The default puppet's rig: hinge knees (+X bends the shin back) and elbows (−X bends the forearm forward).

    Limits are loose human ranges; the torso is stiffer than the limbs so reaching
    moves arms before it bends the back (thesis §4.2.1: shoulder softer than clavicle).
    """
    ball = {
        "spine": ((-0.5, -0.5, -0.4), (0.6, 0.5, 0.4)),
        "chest": ((-0.4, -0.4, -0.3), (0.5, 0.4, 0.3)),
        "neck": ((-0.6, -0.8, -0.4), (0.6, 0.8, 0.4)),
        "head": ((-0.5, -0.6, -0.3), (0.5, 0.6, 0.3)),
        "l_upper_arm": ((-2.6, -1.6, -0.6), (2.6, 1.6, 2.8)),
        "r_upper_arm": ((-2.6, -1.6, -2.8), (2.6, 1.6, 0.6)),
        "l_hand": ((-1.2, -1.4, -0.6), (1.2, 1.4, 0.6)),
        "r_hand": ((-1.2, -1.4, -0.6), (1.2, 1.4, 0.6)),
        "l_upper_leg": ((-2.2, -0.8, -0.5), (0.6, 0.8, 1.2)),
        "r_upper_leg": ((-2.2, -0.8, -1.2), (0.6, 0.8, 0.5)),
        "l_foot": ((-0.8, -0.4, -0.4), (0.9, 0.4, 0.4)),
        "r_foot": ((-0.8, -0.4, -0.4), (0.9, 0.4, 0.4)),
    }
    limits: dict[str, tuple[ArrayLike, ArrayLike]] = dict(ball)
    limits.update(dict.fromkeys(("l_lower_leg", "r_lower_leg", "l_lower_arm", "r_lower_arm"), (0.0, 2.6)))
    stiff = {"hips": 6.0, "spine": 4.0, "chest": 4.0, "neck": 2.0, "head": 2.0}
    hinges = {"l_lower_leg": (1, 0, 0), "r_lower_leg": (1, 0, 0), "l_lower_arm": (-1, 0, 0), "r_lower_arm": (-1, 0, 0)}
    return IKRig.build(skeleton, hinges=hinges, limits=limits, stiffness=stiff, root_translation=root_translation)
