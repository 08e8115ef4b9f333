"""Which way is up in a motion file, judged by the figure it holds, and the figure stood up.

BVH has no up field and nearly every capture keeps Y up, but Blender (and other Z-up
tools) write their own axes: a walk exported from Blender lies flat on its back in a
Y-up world, and its "speed" mixes the stride with the fall of the head. A human figure
says which way is up, as it says its unit: in most frames its head is above its feet.
Each frame votes for the axis (±X, ±Y, ±Z) nearest to its feet-to-head direction, and
the majority wins when it is clear (two thirds of the frames); otherwise the format's
own convention (+Y for BVH and glTF) stands. A figure that *travels* along the voted
axis is crawling or lying in a Y-up file, not standing in another one, so it keeps the
convention too. A figure no joint map reads (a fox, a cylinder) keeps the convention.
``--up`` overrides the judgement.

Standing a figure up is a change of basis ``M`` (the shortest turn taking the up axis to
+Y): every offset, bone tip, translation and root position is turned by ``M`` and every
local rotation conjugated (``M R M⁻¹``), so both the rest pose and the motion stand up
and every world position is exactly the file's, turned.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from engine import quat
from engine.clip import Clip
from engine.fk import forward_kinematics
from engine.skeleton import Skeleton

__all__ = ["AXES", "UpAxis", "figure_height", "given_up", "judge_up", "stood_up"]

AXES: dict[str, NDArray[np.float64]] = {
    name: sign * np.eye(3)[k] for k, axis in enumerate("xyz") for name, sign in ((axis, 1.0), (f"-{axis}", -1.0))
}
"""The axes ``--up`` accepts, by name."""

_MAJORITY = 2.0 / 3.0
_MAX_VOTERS = 400  # frames sampled for the vote (a long take needs no more)


@dataclass(frozen=True)
class UpAxis:
    """An up-axis decision: the axis's name (a key of :data:`AXES`) and why."""

    name: str
    basis: str

    @property
    def vector(self) -> NDArray[np.float64]:
        """The up axis in the file's coordinates."""
        return AXES[self.name]


def given_up(name: str) -> UpAxis:
    """The axis the user named (``--up``); ``ValueError`` listing the known ones otherwise."""
    key = name.strip().lower().lstrip("+")
    if key not in AXES:
        raise ValueError(f"unknown up axis {name!r}; use one of {', '.join(AXES)}")
    return UpAxis(key, "given")


def _snap(v: NDArray[np.float64]) -> NDArray[np.int64]:
    """Index into the six axes ``[x, -x, y, -y, z, -z]`` nearest to each row of ``v``."""
    k = np.argmax(np.abs(v), axis=-1)
    negative = np.take_along_axis(v, k[..., None], axis=-1)[..., 0] < 0
    return 2 * k + negative


def judge_up(clip: Clip, joint_map: dict[str, str] | None = None, convention: str = "y") -> UpAxis:
    """The file's up axis, judged by its figure (see the module docstring).

    Args:
        clip: the motion in file axes (any unit).
        joint_map: puppet joint → source joint, when known (``--joint-map``); else guessed.
        convention: the format's own up axis, kept when the figure does not say otherwise.
    """
    from engine.io.joint_maps import guess_joint_map

    sk = clip.skeleton
    if joint_map is None:
        try:
            _, joint_map, _ = guess_joint_map(sk.names)
        except ValueError:
            return UpAxis(convention, "the format's convention (no joint map reads the figure)")
    top = next((joint_map[j] for j in ("head", "neck", "chest") if joint_map.get(j) in sk.names), None)
    feet = [joint_map[j] for j in ("l_foot", "r_foot") if joint_map.get(j) in sk.names]
    if top is None or not feet:
        return UpAxis(convention, "the format's convention (no head or feet found)")
    frames = np.unique(np.linspace(0, clip.num_frames - 1, min(clip.num_frames, _MAX_VOTERS)).astype(np.int64))
    offsets = None if clip.translations is None else clip.translations[frames]
    pos, _ = forward_kinematics(sk, clip.root[frames], clip.rotations[frames], offsets)
    rise = pos[:, sk.index(top)] - pos[:, [sk.index(f) for f in feet]].mean(axis=1)
    votes = np.bincount(_snap(rise), minlength=6)
    names = [f"{s}{a}" for a in "xyz" for s in ("", "-")]
    best = int(np.argmax(votes))
    share = votes[best] / len(frames)
    if names[best] == convention:
        return UpAxis(convention, f"head above the feet along {convention} in {share:.0%} of frames")
    if share < _MAJORITY:
        return UpAxis(
            convention,
            f"the format's convention (head above the feet along {names[best]} in only {share:.0%} of frames)",
        )
    travel = clip.root[-1] - clip.root[0]
    along = float(np.dot(travel, AXES[names[best]]))
    if abs(along) > 0.5 * float(np.linalg.norm(travel)) and abs(along) > 0.25 * float(
        np.median(np.linalg.norm(rise, axis=1))
    ):
        return UpAxis(
            convention,
            f"the format's convention (the figure travels head first along {names[best]}: lying or crawling)",
        )
    return UpAxis(names[best], f"head above the feet along {names[best]} in {share:.0%} of frames")


def _turn(up: NDArray[np.float64]) -> NDArray[np.float64]:
    """The shortest rotation taking ``up`` to +Y (a half turn about X for -Y)."""
    if up[1] < -0.5:
        return quat.from_axis_angle(np.array([1.0, 0.0, 0.0]), np.float64(np.pi))
    return quat.between(up, np.array([0.0, 1.0, 0.0]))


def stood_up(clip: Clip, up: UpAxis) -> Clip:
    """``clip`` in axes where ``up`` is +Y: every position turned, every rotation conjugated (exact)."""
    if up.name == "y":
        return clip
    m = _turn(up.vector)
    m_inv = quat.conjugate(m)
    sk = clip.skeleton
    skeleton = Skeleton(sk.names, sk.parents, quat.rotate(m, sk.offsets), quat.rotate(m, sk.tips), sk.radii)
    rot = quat.mul(quat.mul(m, clip.rotations), m_inv)
    translations = None if clip.translations is None else quat.rotate(m, clip.translations)
    rm = clip.root_motion
    if rm is not None:
        raise ValueError(f"clip {clip.name!r}: stand a file's clip up before its root motion is extracted")
    return replace(clip, skeleton=skeleton, root=quat.rotate(m, clip.root), rotations=rot, translations=translations)


def figure_height(clip: Clip) -> float:
    """Median over frames of the figure's vertical extent (joints and bone tips), in the clip's units."""
    sk = clip.skeleton
    frames = np.unique(np.linspace(0, clip.num_frames - 1, min(clip.num_frames, _MAX_VOTERS)).astype(np.int64))
    offsets = None if clip.translations is None else clip.translations[frames]
    pos, rot = forward_kinematics(sk, clip.root[frames], clip.rotations[frames], offsets)
    y = np.concatenate([pos[..., 1], (pos + quat.rotate(rot, sk.tips))[..., 1]], axis=1)
    return float(np.median(y.max(axis=1) - y.min(axis=1)))
