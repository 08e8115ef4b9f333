"""Retarget a clip from any humanoid skeleton onto another (the puppet) by a joint-name map.

The method copies **world-space bone directions**: each mapped target joint gets the world
rotation ``T = M · S(t) · A⁻¹ · Rⱼ⁻¹ · B`` where ``S(t)`` is the source joint's world
rotation at time ``t``, ``A`` and ``B`` the source and target rest world rotations, ``M``
turns the source's up axis to +Y, and ``Rⱼ`` aligns the source rest bone with the target
rest bone. ``Rⱼ`` is what makes different rest poses work: a T-posed CMU arm and the
puppet's hanging arm differ by 90°, Bandai's rest has every bone along its local X, and
the iClone rest lies on its back; aligning each bone's rest *direction* (and, for joints
that fan out — hips, chest — their whole frame from two directions) cancels all of it.
Local rotations follow as ``parent⁻¹ · child``; unmapped target joints keep their rest.

The root travels with the source's hips, scaled by the ratio of leg lengths so the
stride fits the puppet's legs and the feet stay on the floor.

The puppet's bones are rigid: a source's translation channel (stretching bones, props)
and scale channel place the source joints (so the hips travel right) but are not carried
over. They are dropped explicitly, with a :class:`RetargetWarning` when they moved a
joint by more than :data:`LARGE_TRANSLATION` of the source's leg length.
"""

from __future__ import annotations

import warnings

import numpy as np
from numpy.typing import NDArray

from engine import quat
from engine.clip import Clip
from engine.fk import forward_kinematics
from engine.io.joint_shape import guess_clip_joint_map
from engine.skeleton import Skeleton

__all__ = ["retarget", "leg_length", "RetargetWarning", "LARGE_TRANSLATION"]

LARGE_TRANSLATION = 0.02  # share of the source leg length


class RetargetWarning(UserWarning):
    """Retargeting dropped motion the puppet cannot play (translation or scale channels)."""

F64 = NDArray[np.float64]
_AXES = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1], [-1, 0, 0], [0, -1, 0], [0, 0, -1]], dtype=np.float64)


def _frame(primary: F64, secondary: F64) -> F64:
    """Orthonormal basis (rows) from a primary direction and a second one roughly across it."""
    a = primary / np.linalg.norm(primary)
    b = secondary - np.dot(secondary, a) * a
    nb = np.linalg.norm(b)
    if nb < 1e-9:
        return quat.to_matrix(quat.between([0.0, 1.0, 0.0], a)).T
    b = b / nb
    return np.stack([a, b, np.cross(a, b)])


def _align(ds: F64, dt: F64, ss: F64 | None = None, st: F64 | None = None) -> F64:
    """Rotation taking source direction ``ds`` to target ``dt`` (and ``ss`` to ``st`` as far as possible)."""
    if np.linalg.norm(ds) < 1e-9 or np.linalg.norm(dt) < 1e-9:
        return quat.identity()
    if ss is None or st is None or np.linalg.norm(ss) < 1e-9 or np.linalg.norm(st) < 1e-9:
        return quat.between(ds, dt)
    return quat.from_matrix(_frame(dt, st).T @ _frame(ds, ss))


def leg_length(skeleton: Skeleton, upper: str, foot: str) -> float:
    """Length of the bone chain from ``upper`` (hip joint) down to ``foot`` (ankle), in rest."""
    chain = skeleton.chain(upper, foot)
    return float(np.linalg.norm(skeleton.offsets[chain[1:]], axis=1).sum())


def _leg_ratio(target: Skeleton, a_pos: F64, tmap: dict[int, int]) -> float:
    """Target leg length over source leg length (mean of the legs both skeletons map), else 1."""
    ratios = []
    for side in ("l", "r"):
        names = [f"{side}_{b}" for b in ("upper_leg", "lower_leg", "foot")]
        if not all(n in target.names and target.index(n) in tmap for n in names):
            continue
        src = [a_pos[tmap[target.index(n)]] for n in names]
        length = np.linalg.norm(src[1] - src[0]) + np.linalg.norm(src[2] - src[1])
        if length > 1e-9:
            ratios.append(leg_length(target, names[0], names[2]) / length)
    return float(np.mean(ratios)) if ratios else 1.0


def _source_dir(src: Skeleton, pos: F64, rot: F64, s: int, aim: int | None) -> F64 | None:
    """Rest world direction of a source leaf bone: towards its aim joint, else its End Site.

    A lone child is *not* trusted: iClone's head has a single ``FacialBone`` pointing at
    the face, which would tip the puppet's head forward by 90°.
    """
    if aim is not None:
        return pos[aim] - pos[s]
    if np.linalg.norm(src.tips[s]) > 1e-9:
        return quat.rotate(rot[s], src.tips[s])
    return None


def _up_rotation(up: F64) -> F64:
    """``M``: the rotation taking the source's up axis (snapped to ±X/Y/Z) to +Y."""
    axis = _AXES[int(np.argmax(_AXES @ up))]
    return quat.between(axis, [0.0, 1.0, 0.0])


def _floor_level(target: Skeleton, root: F64, local: F64) -> float:
    """Height of the floor the feet stand on: the 5th percentile over frames of the lowest foot point.

    Feet are the joints named ``*foot*`` (or, failing that, every leaf); a point is the joint
    or its bone tip. A low percentile rather than the minimum ignores a frame or two of
    toe dipping, and a jump's flight frames do not count since the feet are high there.
    """
    wpos, wrot = forward_kinematics(target, root, local)
    feet = [j for j, n in enumerate(target.names) if "foot" in n.lower()]
    if not feet:
        feet = [j for j in range(target.num_joints) if not target.children(j)]
    pts = np.concatenate([wpos[:, feet, 1], (wpos[:, feet] + quat.rotate(wrot[:, feet], target.tips[feet]))[..., 1]], 1)
    return float(np.percentile(pts.min(axis=1), 5.0))


def _warn_dropped(clip: Clip, target: Skeleton, a_pos: F64, tmap: dict[int, int]) -> None:
    """Warn when the translation or scale channel the puppet cannot play moved joints noticeably."""
    if clip.translations is None and clip.scales is None:
        return
    src = clip.skeleton
    rigid, _ = forward_kinematics(src, clip.root, clip.rotations)
    full, _ = forward_kinematics(src, clip.root, clip.rotations, clip.translations, clip.scales)
    moved = np.linalg.norm(full - rigid, axis=-1).max(axis=0)  # [J] largest displacement per joint
    scale = max(_source_leg(target, a_pos, tmap), 1e-9)
    worst = int(np.argmax(moved))
    if moved[worst] > LARGE_TRANSLATION * scale:
        channels = " and ".join(n for n, v in (("translation", clip.translations), ("scale", clip.scales)) if v is not None)
        warnings.warn(RetargetWarning(
            f"clip {clip.name!r}: the puppet's bones are rigid; its {channels} channel is dropped, which moves "
            f"{src.names[worst]!r} by up to {moved[worst]:.3g} m ({moved[worst] / scale:.0%} of the leg)"), stacklevel=3)


def _source_leg(target: Skeleton, a_pos: F64, tmap: dict[int, int]) -> float:
    """Source leg length (hip to foot joint, rest) through the map, or the rest figure's extent."""
    legs = []
    for side in ("l", "r"):
        names = [f"{side}_{b}" for b in ("upper_leg", "lower_leg", "foot")]
        if all(n in target.names and target.index(n) in tmap for n in names):
            pts = a_pos[[tmap[target.index(n)] for n in names]]
            legs.append(float(np.linalg.norm(np.diff(pts, axis=0), axis=1).sum()))
    return float(np.mean(legs)) if legs else float(np.ptp(a_pos, axis=0).max())


def retarget(
    clip: Clip,
    target: Skeleton,
    joint_map: dict[str, str] | None = None,
    aims: dict[str, str] | None = None,
    root_scale: float | None = None,
    name: str | None = None,
    floor: bool = True,
) -> Clip:
    """``clip`` played by ``target``.

    Args:
        clip: source motion (any skeleton, any rest pose, any up axis); root motion is
            baked into its root first, so the retargeted clip travels in its root track.
        target: the skeleton to drive, e.g. ``engine.humanoid.humanoid_skeleton()``.
        joint_map: target joint name → source joint name; guessed from the source names
            (:func:`~engine.io.joint_maps.guess_joint_map`) when ``None``, or, for names of no
            known family, from the figure's shape (:func:`~engine.io.joint_shape.guess_clip_joint_map`).
        aims: target leaf joint → source joint its bone points at (see ``joint_maps.AIMS``).
        root_scale: factor on the root's travel; default: target / source leg length.
        name: the new clip's name (default: the source's).
        floor: shift the motion vertically so the puppet's feet touch y = 0 (see
            :func:`_floor_level`); off, the hips keep the scaled source height, which
            leaves the feet a few centimetres off when ankle heights differ.
    """
    clip = clip.baked_root_motion()  # the source's world travel is what the puppet's root follows
    src = clip.skeleton
    if joint_map is None:
        _, joint_map, guessed_aims = guess_clip_joint_map(clip)
        aims = guessed_aims if aims is None else aims
    aims = aims or {}
    tmap = {target.index(t): src.index(s) for t, s in joint_map.items()}
    if 0 not in tmap:
        raise ValueError(f"the joint map must map the target root {target.names[0]!r}")
    aim_idx = {target.index(t): src.index(s) for t, s in aims.items()}

    s_pos, s_rot = forward_kinematics(src, clip.root, clip.rotations, clip.translations, clip.scales)
    a_pos, a_rot = forward_kinematics(src, src.offsets[0], quat.identity(src.num_joints))
    _warn_dropped(clip, target, a_pos, tmap)
    b_pos, b_rot = forward_kinematics(target, target.offsets[0], quat.identity(target.num_joints))
    root_src = tmap[0]

    # Up axis of the motion: from the hips towards the mapped joints above them (spine…head).
    upper = [tmap[j] for j in range(1, target.num_joints) if j in tmap and b_pos[j, 1] > b_pos[0, 1] + 1e-6]
    up = (s_pos[:, upper].mean(axis=1) - s_pos[:, root_src]).mean(axis=0) if upper else np.array([0.0, 1.0, 0.0])
    m = _up_rotation(up)

    align = np.empty((target.num_joints, 4))
    for j in range(target.num_joints):
        align[j] = quat.IDENTITY if j == 0 or int(target.parents[j]) < 0 else align[int(target.parents[j])]
        if j not in tmap:
            continue
        s = tmap[j]
        kids = [k for k in target.children(j) if k in tmap]
        if kids:
            ds, dt = a_pos[tmap[kids[0]]] - a_pos[s], b_pos[kids[0]] - b_pos[j]
            ss = st = None
            if len(kids) >= 3:
                ss, st = a_pos[tmap[kids[1]]] - a_pos[tmap[kids[2]]], b_pos[kids[1]] - b_pos[kids[2]]
            elif len(kids) == 2:
                ss, st = a_pos[tmap[kids[1]]] - a_pos[s], b_pos[kids[1]] - b_pos[j]
            align[j] = _align(ds, dt, ss, st)
        else:
            ds = _source_dir(src, a_pos, a_rot, s, aim_idx.get(j))
            dt = quat.rotate(b_rot[j], target.tips[j])
            p = int(target.parents[j])
            if ds is None and p in tmap:
                # No End Site or aim (DAZ head: two eyes; hands: five fingers):
                # take the leaf as continuing its parent bone, in both skeletons.
                ds, dt = a_pos[s] - a_pos[tmap[p]], b_pos[j] - b_pos[p]
            if ds is not None and np.linalg.norm(dt) > 1e-9:
                align[j] = _align(ds, dt)

    frames = clip.num_frames
    world = np.empty((frames, target.num_joints, 4))
    local = np.empty_like(world)
    for j in range(target.num_joints):
        p = int(target.parents[j])
        if j in tmap:
            s = tmap[j]
            delta = quat.mul(quat.mul(m, s_rot[:, s]), quat.conjugate(a_rot[s]))
            world[:, j] = quat.mul(quat.mul(delta, quat.conjugate(align[j])), b_rot[j])
            local[:, j] = world[:, j] if p < 0 else quat.mul(quat.conjugate(world[:, p]), world[:, j])
        else:
            local[:, j] = quat.IDENTITY
            world[:, j] = quat.IDENTITY if p < 0 else world[:, p]

    if root_scale is None:
        root_scale = _leg_ratio(target, a_pos, tmap)
    root = root_scale * quat.rotate(m, s_pos[:, root_src])
    if floor:
        root[:, 1] -= _floor_level(target, root, local)
    return Clip(name or clip.name, target, clip.fps, root, local, loop=clip.loop, markers=dict(clip.markers))
