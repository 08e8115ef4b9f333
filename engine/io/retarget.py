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

from engine import quat
from engine.arrays import F64
from engine.clip import Clip, RootMotion
from engine.fk import forward_kinematics
from engine.io.joint_shape import guess_clip_joint_map
from engine.skeleton import Skeleton

__all__ = ["retarget", "retarget_proportions", "leg_length", "RetargetWarning", "LARGE_TRANSLATION"]

LARGE_TRANSLATION = 0.02  # share of the source leg length


class RetargetWarning(UserWarning):
    """Retargeting dropped motion the puppet cannot play (translation or scale channels)."""


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
        channels = " and ".join(
            n for n, v in (("translation", clip.translations), ("scale", clip.scales)) if v is not None
        )
        warnings.warn(
            RetargetWarning(
                f"clip {clip.name!r}: the puppet's bones are rigid; its {channels} channel is dropped, which moves "
                f"{src.names[worst]!r} by up to {moved[worst]:.3g} m ({moved[worst] / scale:.0%} of the leg)"
            ),
            stacklevel=3,
        )


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


def retarget_proportions(clip: Clip, target: Skeleton, name: str | None = None) -> Clip:
    """``clip`` played by a skeleton of the same joints and rest convention with other bone lengths.

    A character built on the puppet's roles (:mod:`engine.character.rig`) stands like the puppet
    when every rotation is the identity, so the puppet's clips need no direction alignment: the
    local rotations carry over as they are. What changes is size: the root's travel, height and
    root motion scale by the ratio of leg lengths (so a stride fits the legs and a planted foot
    stays planted when the proportions match), and the motion is lifted or lowered so the lowest
    foot point sits as high above the floor as it did on the source (:func:`_floor_level`).
    Markers, loop and frame rate are kept.

    Raises:
        ValueError: the skeletons differ in joints or hierarchy.
    """
    src = clip.skeleton
    if src.names != target.names or not np.array_equal(src.parents, target.parents):
        raise ValueError(f"clip {clip.name!r}: the target must have the same joints and hierarchy as its skeleton")
    ends = [(f"{s}_upper_leg", f"{s}_foot") for s in ("l", "r")]
    ratios = [
        leg_length(target, *leg) / leg_length(src, *leg)
        for leg in ends
        if all(n in src.names for n in leg) and leg_length(src, *leg) > 1e-9
    ]
    k = float(np.mean(ratios)) if ratios else float(target.offsets[0, 1] / max(src.offsets[0, 1], 1e-9))
    root = k * np.asarray(clip.root, dtype=np.float64)
    floor = _floor_level(src, clip.root, clip.rotations)
    root[:, 1] += floor - _floor_level(target, root, clip.rotations)
    rotations = np.array(clip.rotations)
    legs = [[target.index(n) for n in leg] for leg in _LEGS if all(n in target.names for n in leg)]
    goals = [_ankle_goal(clip, target, leg, k) for leg in legs]
    if legs:
        root[:, 1] -= _reach_drop(target, root, rotations, legs, goals)
    for leg, goal in zip(legs, goals):
        _plant_leg(clip, target, root, rotations, leg, goal)
    motion = clip.root_motion
    if motion is not None:
        motion = RootMotion(k * np.asarray(motion.translation, dtype=np.float64), np.array(motion.heading))
    return Clip(
        name or clip.name,
        target,
        clip.fps,
        root,
        rotations,
        loop=clip.loop,
        root_motion=motion,
        markers=dict(clip.markers),
    )


_LEGS = (("l_upper_leg", "l_lower_leg", "l_foot"), ("r_upper_leg", "r_lower_leg", "r_foot"))


def _ankle_goal(clip: Clip, target: Skeleton, leg: list[int], k: float) -> F64:
    """``[F,3]`` where the target's ankle goes so its toe tip follows the source's: scaled by ``k`` across the
    floor, at the source's height above it."""
    src = clip.skeleton
    foot = leg[2]
    s_pos, s_rot = forward_kinematics(src, clip.root, clip.rotations)
    toe = s_pos[:, foot] + quat.rotate(s_rot[:, foot], src.tips[foot])
    goal = k * toe
    goal[:, 1] = toe[:, 1]  # the source's clearance, not scaled: a smaller character's toes still clear the floor
    return goal - quat.rotate(s_rot[:, foot], target.tips[foot])


def _reach_drop(
    target: Skeleton, root: F64, rotations: F64, legs: list[list[int]], goals: list[F64], most: float = 0.995
) -> float:
    """How far to lower the whole clip so every ankle goal is within ``most`` of its leg's length.

    The character's ankle may sit higher over its sole than the source's, scaled: standing the
    hips as high as the source's, scaled, would leave its legs a few centimetres short."""
    pos, _ = forward_kinematics(target, root, rotations)
    drop = 0.0
    for leg, goal in zip(legs, goals):
        reach = most * float(np.linalg.norm(target.offsets[leg[1]]) + np.linalg.norm(target.offsets[leg[2]]))
        d = pos[:, leg[0]] - goal
        across = np.minimum(d[:, 0] ** 2 + d[:, 2] ** 2, reach**2)
        drop = max(drop, float(np.max(d[:, 1] - np.sqrt(reach**2 - across))))
    return max(drop, 0.0)


def _plant_leg(clip: Clip, target: Skeleton, root: F64, rotations: F64, leg: list[int], ankle: F64) -> None:
    """Re-solve one leg of :func:`retarget_proportions` so its ankle reaches ``ankle`` (:func:`_ankle_goal`).

    Copied rotations keep a foot planted only when every leg bone scales alike; a character's
    foot is rarely the puppet's foot scaled (CesiumMan's ankle is high, its toes long), so a
    heel-off rolling over the puppet's toe would roll the character's toe forward. The foot
    keeps the source's world rotation and the two-bone leg solve (knee towards where the
    source's knee points) reaches the ankle that puts the toe on its goal. ``rotations`` is
    changed in place.
    """
    from engine.clips._legik import solve_leg

    upper, lower, foot = leg
    _, s_rot = forward_kinematics(clip.skeleton, clip.root, clip.rotations)
    t_pos, t_rot = forward_kinematics(target, root, rotations)
    pole = quat.rotate(s_rot[:, upper], np.array([0.0, 0.0, 1.0]))
    parent = int(target.parents[upper])
    thigh = float(np.linalg.norm(target.offsets[lower]))
    shin = float(np.linalg.norm(target.offsets[foot]))
    sol = solve_leg(t_pos[:, upper], t_rot[:, parent], ankle, pole, s_rot[:, foot], thigh, shin)
    rotations[:, upper], rotations[:, lower], rotations[:, foot] = sol.upper, sol.knee, sol.foot
