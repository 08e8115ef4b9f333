"""Foot placement on uneven ground (like FinalIK's Grounder), via two-bone IK on the legs.

Clips are authored on flat ground at ``y = 0``. For each foot we read how high its
sole is above that flat ground in the clip, look up the real ground under it
(``ground(x, z) -> (height, normal)``), and ask the leg to put the sole that high
above the real ground, with the foot turned to the ground's slope (fully when
planted, fading out as the foot lifts). The pelvis moves by the lowest foot's
height change, so a foot stepping into a dip is reached by lowering the body
rather than over-stretching a leg, and the other knee bends instead.

One puppet's legs are a few dozen 3-vector operations, so they run on floats
(:mod:`engine.ik._scalar`, :mod:`engine.ik._limb`); only the ground query sees numpy.
A crowd of one skeleton goes through :func:`ground_feet_batch` instead: the same steps
as arrays over the puppets, or, with numba (:mod:`engine.jit`), as compiled loops over
them (:mod:`engine.ik._ground_kernel`; only the ground query and the foot locks stay numpy).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from engine import jit, quat
from engine.columns import Columns
from engine.fk import kernel_array
from engine.ik import _ground_kernel as _kernel
from engine.ik._limb import solve_limb
from engine.ik._scalar import Q_ID, add, between, chain_fk, qmul, qnormalize, qrot, slerp, sub
from engine.ik._vec import path_fk
from engine.ik.foot_lock import FootLock, floor_lift, lock_feet, smoothstep
from engine.pose import Pose
from engine.skeleton import Skeleton

__all__ = [
    "GroundQuery",
    "PlaneGround",
    "HeightfieldGround",
    "Leg",
    "HUMANOID_LEGS",
    "ground_feet",
    "ground_feet_batch",
]

from engine.arrays import F64 as F

GroundQuery = Callable[[F, F], tuple[F, F]]
_UP = (0.0, 1.0, 0.0)
_STILL = 0.1  # m/s: an animated toe slower than this has found its standing place
#: The defaults of :func:`ground_feet` / :func:`ground_feet_batch` (the crowd pass of :mod:`engine.ik.crowd` uses them).
ALIGN_HEIGHT, CONTACT_HEIGHT, MAX_PELVIS_SHIFT = 0.25, 0.03, 0.5


@dataclass(frozen=True)
class PlaneGround:
    """A plane through ``point`` with ``normal`` (a slope, or flat ground with the default normal)."""

    point: tuple[float, float, float] = (0.0, 0.0, 0.0)
    normal: tuple[float, float, float] = (0.0, 1.0, 0.0)

    @cached_property
    def frame(self) -> tuple[F, F]:
        """``(point, unit normal)`` as arrays (made once: a crowd asks every step)."""
        n = np.asarray(self.normal, dtype=np.float64)
        n = n / np.linalg.norm(n)
        if n[1] < 1e-6:
            raise ValueError("ground plane must not be vertical")
        return np.asarray(self.point, dtype=np.float64), n

    def __call__(self, x: ArrayLike, z: ArrayLike) -> tuple[F, F]:
        """Height ``[...]`` and unit normal ``[...,3]`` under ``(x, z)``."""
        p, n = self.frame
        x, z = np.asarray(x, dtype=np.float64), np.asarray(z, dtype=np.float64)
        h = p[1] - (n[0] * (x - p[0]) + n[2] * (z - p[2])) / n[1]
        return h, np.broadcast_to(n, h.shape + (3,)).copy()


@dataclass(frozen=True)
class HeightfieldGround:
    """A regular grid of heights (bilinear), ``heights[i, k]`` at ``x = x0 + i·cell``, ``z = z0 + k·cell``."""

    heights: F
    cell: float
    x0: float = 0.0
    z0: float = 0.0

    def __call__(self, x: ArrayLike, z: ArrayLike) -> tuple[F, F]:
        """Height and normal under ``(x, z)``; points off the grid take the nearest edge."""
        h = np.asarray(self.heights, dtype=np.float64)
        fx = np.clip((np.asarray(x, dtype=np.float64) - self.x0) / self.cell, 0.0, h.shape[0] - 1.000001)
        fz = np.clip((np.asarray(z, dtype=np.float64) - self.z0) / self.cell, 0.0, h.shape[1] - 1.000001)
        i, k = np.floor(fx).astype(int), np.floor(fz).astype(int)
        u, v = fx - i, fz - k
        h00, h10, h01, h11 = h[i, k], h[i + 1, k], h[i, k + 1], h[i + 1, k + 1]
        height = (1 - u) * (1 - v) * h00 + u * (1 - v) * h10 + (1 - u) * v * h01 + u * v * h11
        dhdx = ((1 - v) * (h10 - h00) + v * (h11 - h01)) / self.cell
        dhdz = ((1 - u) * (h01 - h00) + u * (h11 - h10)) / self.cell
        n = np.stack([-dhdx, np.ones_like(dhdx), -dhdz], axis=-1)
        return height, n / np.linalg.norm(n, axis=-1, keepdims=True)


@dataclass(frozen=True)
class Leg:
    """A leg's joints, the knee's pole direction in the hips' frame, the sole centre and the
    back of the heel in the foot's frame (the toe tip is the foot bone's tip)."""

    upper: str
    lower: str
    foot: str
    sole: tuple[float, float, float]
    knee_forward: tuple[float, float, float] = (0.0, 0.0, 1.0)
    heel: tuple[float, float, float] = (0.0, -0.05, -0.05)


# The humanoid's sole centre: under the ankle, half-way to the toe tip (tips: (0, -0.05, 0.15)).
HUMANOID_LEGS: tuple[Leg, ...] = (
    Leg("l_upper_leg", "l_lower_leg", "l_foot", (0.0, -0.05, 0.075)),
    Leg("r_upper_leg", "r_lower_leg", "r_foot", (0.0, -0.05, 0.075)),
)


def _lock_and_lift(
    skeleton: Skeleton,
    legs: tuple[Leg, ...],
    targets: F,
    new_rot: F,
    floor: F,
    normal: F,
    locks: Sequence[FootLock | None] | None,
    dt: float,
    weight: F,
) -> F:
    """Ankle targets ``[P, L, 3]`` with no toe or heel under the ground and planted feet locked
    (position and heading: ``new_rot [P, L, 4]``, the feet's rotations, is turned in place).

    ``floor [P, L, 3]`` is the ground point under each sole and ``normal`` its normal: toe
    and heel are kept on the positive side of that tangent plane (a foot on a slope is
    measured along the slope). ``weight [P]`` scales the lift like the rest of the
    grounding; a puppet whose lock has no ``contacts`` this step is only lifted."""
    tips = np.array([skeleton.tips[skeleton.index(leg.foot)] for leg in legs])
    heels = np.array([leg.heel for leg in legs])
    toes = targets + quat.rotate(new_rot, tips)
    backs = targets + quat.rotate(new_rot, heels)
    n = (1.0 - weight[:, None, None]) * np.array(_UP) + weight[:, None, None] * normal
    n = n / np.linalg.norm(n, axis=-1, keepdims=True)
    depth = np.stack([((toes - floor) * n).sum(-1), ((backs - floor) * n).sum(-1)], axis=-1)
    lift = floor_lift(depth, np.zeros(depth.shape[:-1])) / n[..., 1]
    targets = targets.copy()
    targets[..., 1] += lift
    toes[..., 1] += lift
    if locks is not None:
        _apply_locks(locks, targets, new_rot, toes, floor, tips, dt)
    return targets


def _apply_locks(
    locks: Sequence[FootLock | None],
    targets: F,
    new_rot: F,
    toes: F,
    floor: F,
    tips: F,
    dt: float,
    cols: Columns | None = None,
) -> None:
    """Hold planted toes where they landed: ``targets`` and ``new_rot`` changed in place, the locks advanced."""
    groups: dict[tuple[float, ...], list[int]] = {}
    held: dict[int, FootLock] = {}
    for p, lock in enumerate(locks):
        if lock is not None and lock.contacts is not None and lock.enabled:
            _fit_lock(lock, toes[p])
            groups.setdefault(lock.settings(), []).append(p)
            held[p] = lock
    for members in groups.values():  # puppets whose locks share settings: one array pass
        _lock_group(np.array(members), [held[p] for p in members], targets, new_rot, toes, floor, tips, dt, cols)


def _fit_lock(lock: FootLock, toes: F) -> None:
    """Give a fresh (or resized) lock its per-leg arrays, nothing held."""
    count = len(toes)
    if lock.weights.shape != (count,) or lock.stepping.shape != (count,) or lock.animated.shape != (count, 3):
        lock.points, lock.weights, lock.animated = np.zeros((count, 3)), np.zeros(count), toes.copy()
        lock.planted, lock.stepping = np.zeros(count, dtype=bool), np.zeros(count, dtype=bool)
    if lock.yaw.shape != (count,):
        lock.yaw = np.full(count, np.nan)


def _lock_group(
    idx: NDArray[np.int64],
    group: list[FootLock],
    targets: F,
    new_rot: F,
    toes: F,
    floor: F,
    tips: F,
    dt: float,
    cols: Columns | None = None,
) -> None:
    """Lock the feet of puppets ``idx`` (their ``group`` of locks, one setting) in place, as arrays ``[G, L]``."""
    if jit.enabled():
        _lock_group_compiled(idx, group, targets, new_rot, floor, tips, dt, cols)
        return
    weights = np.stack([g.weights for g in group])
    # A planted foot keeps the heading it landed with while the body turns above it
    # (a foot that turned with the hips would sweep its toe or heel over the ground).
    fwd = quat.rotate(new_rot[idx], np.array([0.0, 0.0, 1.0]))
    yaw = np.arctan2(fwd[..., 0], fwd[..., 2])
    held_yaw = np.where(weights > 0.0, np.stack([g.yaw for g in group]), yaw)
    twist = (held_yaw - yaw + np.pi) % (2 * np.pi) - np.pi
    new_rot[idx] = quat.mul(quat.from_axis_angle(np.array(_UP), twist * smoothstep(weights)), new_rot[idx])
    toe = targets[idx] + quat.rotate(new_rot[idx], tips)
    animated = np.stack([g.animated for g in group])
    still = np.linalg.norm((toe - animated)[..., [0, 2]], axis=-1) <= _STILL * max(dt, 1e-9)
    contacts = np.stack([np.broadcast_to(np.asarray(g.contacts, dtype=np.float64), (tips.shape[0],)) for g in group])
    points, weights, planted, stepping, placed = lock_feet(
        np.stack([g.points for g in group]),
        weights,
        np.stack([g.planted for g in group]),
        np.stack([g.stepping for g in group]),
        toe,
        contacts,
        toe[..., 1] - floor[idx, :, 1],
        np.abs(twist),
        np.array([g.settle for g in group]),
        still,
        dt,
        group[0],
    )
    for k, g in enumerate(group):
        g.points, g.weights, g.planted, g.stepping = points[k], weights[k], planted[k], stepping[k]
        g.yaw, g.animated = held_yaw[k], toe[k].copy()
    targets[idx] += placed - toe


def _lock_group_compiled(
    idx: NDArray[np.int64],
    group: list[FootLock],
    targets: F,
    new_rot: F,
    floor: F,
    tips: F,
    dt: float,
    cols: Columns | None = None,
) -> None:
    """:func:`_lock_group` on the compiled kernel: the locks' state as ``[G, L]`` arrays, one pass.

    With ``cols`` the state stays in columns the locks view (:mod:`engine.columns`), which the
    kernel updates in place; without, it is gathered from the locks and each given its rows back."""
    legs = tips.shape[0]
    state = _lock_state(group, legs, cols)
    _kernel.lock_group(
        np.asarray(idx, dtype=np.int64),
        targets,
        new_rot,
        np.ascontiguousarray(floor),
        np.ascontiguousarray(tips, dtype=np.float64),
        dt,
        np.array(group[0].settings()),
        state["points"],
        state["weights"],
        state["planted"],
        state["stepping"],
        state["yaw"],
        state["animated"],
        _lock_contacts(group, legs, cols),
        np.array([g.settle for g in group], dtype=bool),
    )
    if cols is not None:
        for name in _LOCK_STATE:
            cols.get(FootLock, name, legs, _LOCK_TYPES.get(name, np.float64)).write(group, state[name])
        return
    for k, g in enumerate(group):
        g.points, g.weights, g.planted, g.stepping = (state[n][k] for n in ("points", "weights", "planted", "stepping"))
        g.yaw, g.animated = state["yaw"][k], state["animated"][k]


#: The lock state the compiled kernel advances in place, in its argument order, and the non-float fields.
_LOCK_STATE = ("points", "weights", "planted", "stepping", "yaw", "animated")
_LOCK_TYPES: dict[str, type] = {"planted": np.bool_, "stepping": np.bool_}


def _lock_state(group: list[FootLock], legs: int, cols: Columns | None) -> dict[str, NDArray[Any]]:
    """The locks' state fields as writable C-contiguous ``[G, L…]`` arrays (the columns themselves, given ``cols``)."""
    if cols is None:
        return {
            name: np.array([getattr(g, name) for g in group], dtype=_LOCK_TYPES.get(name, np.float64))
            for name in _LOCK_STATE
        }
    return {name: cols.get(FootLock, name, legs, _LOCK_TYPES.get(name, np.float64)).read(group) for name in _LOCK_STATE}


def _lock_contacts(group: list[FootLock], legs: int, cols: Columns | None) -> F:
    """The locks' contact votes ``[G, L]`` (a vote given as one number holds for every leg)."""
    try:
        if cols is not None:
            contacts = cols.get(FootLock, "contacts", legs).read(group)
        else:
            contacts = np.array([g.contacts for g in group], dtype=np.float64)
    except ValueError:  # ragged: some puppet's vote is one number for every leg
        contacts = np.zeros(0)
    if contacts.shape != (len(group), legs):
        contacts = np.stack([np.broadcast_to(np.asarray(g.contacts, dtype=np.float64), (legs,)) for g in group])
    return contacts


def _reach_shift(hips: F, targets: F, lengths: F, shift: F, max_pelvis_shift: float) -> F:
    """Lower the pelvis ``shift [P]`` further where an ankle target ``[P, L, 3]`` lies beyond its leg's
    reach (``lengths [P, L]``) from its hip ``[P, L, 3]``: a foot held back by its lock, or on a
    step down, is reached by bending the knees, as FinalIK's grounder does, never by a leg
    that dangles short of the ground."""
    reach = lengths - 1e-4  # a straight leg in the clip stays straight
    dxz = np.linalg.norm((targets - hips)[..., [0, 2]], axis=-1)
    dy = hips[..., 1] + shift[:, None] - targets[..., 1]
    need = np.where(dxz < reach, dy - np.sqrt(np.maximum(reach**2 - dxz**2, 0.0)), 0.0)
    return np.maximum(shift - np.maximum(need, 0.0).max(axis=-1), -max_pelvis_shift)


def ground_feet(
    skeleton: Skeleton,
    pose: Pose,
    ground: GroundQuery,
    legs: tuple[Leg, ...] = HUMANOID_LEGS,
    *,
    offsets: ArrayLike | None = None,
    align_height: float = ALIGN_HEIGHT,
    contact_height: float = CONTACT_HEIGHT,
    max_pelvis_shift: float = MAX_PELVIS_SHIFT,
    weight: float = 1.0,
    lock: FootLock | None = None,
    dt: float = 0.0,
) -> np.float64:
    """Plant one puppet's feet on ``ground`` in place; returns the pelvis height change applied.

    Args:
        skeleton, pose: the puppet and its animated pose (one puppet; root is world space).
        ground: ``ground(x, z) -> (height, normal)``.
        legs: which limbs are legs and where their soles are.
        align_height: sole height (m) above which a lifted foot no longer follows the slope.
        contact_height: sole height (m) below which the foot counts as planted (fully aligned).
        max_pelvis_shift: largest pelvis move (m), either way.
        weight: 0..1 blend of the whole effect.
        lock: the puppet's :class:`~engine.ik.foot_lock.FootLock` (updated in place); planted
            toes stay where they landed. ``dt`` is the step it advances by.
    """
    if not 0.0 <= weight <= 1.0:
        raise ValueError("weight must lie in 0..1")
    idx = [(skeleton.index(leg.upper), skeleton.index(leg.lower), skeleton.index(leg.foot)) for leg in legs]
    par = skeleton.parents
    off = (skeleton.offsets if offsets is None else np.asarray(offsets, dtype=np.float64)).tolist()
    rot = pose.rotations.tolist()
    root = tuple(pose.root.tolist())
    ankle, qfoot, sole, hips = [], [], [], []
    for (u, _, f), leg in zip(idx, legs, strict=True):
        wp, wr = chain_fk(par, root, rot, off, f)
        ankle.append(wp[f])
        qfoot.append(wr[f])
        hips.append(wp[u])
        sole.append(add(wp[f], qrot(wr[f], leg.sole)))
    clip_height = [s[1] for s in sole]  # authored on flat ground at y = 0
    height, normal = ground(np.array([s[0] for s in sole]), np.array([s[2] for s in sole]))
    height, normal = np.asarray(height, dtype=np.float64), np.asarray(normal, dtype=np.float64)
    if not (np.all(np.isfinite(height)) and np.all(np.isfinite(normal))):
        raise ValueError("ground query returned non-finite values")
    height, normal = np.broadcast_to(height, (len(legs),)).tolist(), np.broadcast_to(normal, (len(legs), 3)).tolist()
    # Turn each foot to the slope, fading out as it lifts; its sole keeps the clip's clearance.
    targets, new_rot = [], []
    for leg, q, s, ch, h, n in zip(legs, qfoot, sole, clip_height, height, normal, strict=True):
        planted = min(max((align_height - ch) / (align_height - contact_height), 0.0), 1.0) * weight
        r = qmul(slerp(Q_ID, between(_UP, n), planted), q)
        new_rot.append(r)
        targets.append(sub((s[0], h * weight + ch, s[2]), qrot(r, leg.sole)))
    floor = np.array([[(sl[0], h * weight, sl[2]) for sl, h in zip(sole, height, strict=True)]])
    rotations = np.array([new_rot])
    fixed = _lock_and_lift(
        skeleton,
        legs,
        np.array([targets]),
        rotations,
        floor,
        np.array([normal]),
        None if lock is None else [lock],
        dt,
        np.array([weight]),
    )[0]
    targets = [tuple(t) for t in fixed.tolist()]
    new_rot = [tuple(r) for r in rotations[0].tolist()]
    # Pelvis: follow the lowest foot (negative into dips, positive onto steps).
    shift = min(max(min(t[1] - a[1] for t, a in zip(targets, ankle)), -max_pelvis_shift), max_pelvis_shift)
    lengths = np.array([[np.linalg.norm(off[lo]) + np.linalg.norm(off[f]) for _, lo, f in idx]])
    shift = float(_reach_shift(np.array([hips]), np.array([targets]), lengths, np.array([shift]), max_pelvis_shift)[0])
    pose.root[1] += shift
    root = tuple(pose.root.tolist())
    for leg, (u, lo, f), tgt, frot in zip(legs, idx, targets, new_rot, strict=True):
        wp, wr = chain_fk(par, root, rot, off, lo)
        pole = add(wp[lo], qrot(wr[int(par[u])], leg.knee_forward))
        solve_limb(par, root, rot, off, (u, lo, f), tgt, pole, qnormalize(frot))
        for j in (u, lo, f):
            pose.rotations[j] = rot[j]
    return np.float64(shift)


def ground_feet_batch(
    skeleton: Skeleton,
    roots: F,
    rotations: F,
    ground: GroundQuery,
    legs: tuple[Leg, ...] = HUMANOID_LEGS,
    *,
    offsets: ArrayLike | None = None,
    align_height: float = ALIGN_HEIGHT,
    contact_height: float = CONTACT_HEIGHT,
    max_pelvis_shift: float = MAX_PELVIS_SHIFT,
    weight: ArrayLike = 1.0,
    locks: Sequence[FootLock | None] | None = None,
    dt: float = 0.0,
    lock_columns: Columns | None = None,
) -> F:
    """:func:`ground_feet` for ``P`` puppets of one skeleton at once, in place.

    The same steps as the one-puppet version, as arrays ``[P, …]``: leg FK, one ground
    query for every sole, foot alignment, the pelvis shift and the batched
    :func:`~engine.ik.two_bone.two_bone_ik` per leg; a crowd costs a few dozen numpy
    calls instead of a Python loop of float maths per puppet.

    Args:
        roots: ``[P,3]`` world roots (the pelvis shift is added to them).
        rotations: ``[P,J,4]`` local rotations (the legs are solved in them).
        offsets: ``[J,3]`` or ``[P,J,3]`` bone offsets.
        weight: ``[P]`` (or one) 0..1 blend of the whole effect.
        locks: per puppet, its :class:`~engine.ik.foot_lock.FootLock` (or ``None``), advanced by ``dt``.
        lock_columns: where the compiled path keeps the locks' state as columns
            (:mod:`engine.columns`: no gather and scatter per step); without it, gathered.

    Returns:
        ``[P]`` pelvis height changes applied.
    """
    from engine.ik.two_bone import two_bone_ik

    w = np.broadcast_to(np.asarray(weight, dtype=np.float64), (len(roots),))
    if np.any((w < 0.0) | (w > 1.0)):
        raise ValueError("weight must lie in 0..1")
    off = skeleton.offsets if offsets is None else np.asarray(offsets, dtype=np.float64)
    idx = [(skeleton.index(leg.upper), skeleton.index(leg.lower), skeleton.index(leg.foot)) for leg in legs]
    if jit.enabled():
        return _ground_compiled(
            skeleton,
            roots,
            rotations,
            ground,
            legs,
            off,
            idx,
            align_height,
            contact_height,
            max_pelvis_shift,
            w,
            locks,
            dt,
            lock_columns,
        )
    soles = np.array([leg.sole for leg in legs])
    ankle, qfoot, hip = [], [], []
    for u, _, f in idx:
        wp, wr = path_fk(skeleton, roots, rotations, f, off)
        ankle.append(wp[f])
        qfoot.append(wr[f])
        hip.append(wp[u])
    ankles, qfeet = np.stack(ankle, axis=1), np.stack(qfoot, axis=1)  # [P,L,3], [P,L,4]
    sole = ankles + quat.rotate(qfeet, soles)
    clip_height = sole[..., 1]  # authored on flat ground at y = 0
    height, normal = ground(sole[..., 0], sole[..., 2])
    height = np.broadcast_to(np.asarray(height, dtype=np.float64), clip_height.shape)
    normal = np.broadcast_to(np.asarray(normal, dtype=np.float64), sole.shape)
    if not (np.all(np.isfinite(height)) and np.all(np.isfinite(normal))):
        raise ValueError("ground query returned non-finite values")
    planted = np.clip((align_height - clip_height) / (align_height - contact_height), 0.0, 1.0) * w[:, None]
    tilt = quat.between(np.broadcast_to(_UP, normal.shape), normal)
    new_rot = quat.mul(quat.slerp(quat.identity(*planted.shape), tilt, planted), qfeet)
    flat = np.stack([sole[..., 0], height * w[:, None] + clip_height, sole[..., 2]], axis=-1)
    floor = np.stack([sole[..., 0], height * w[:, None], sole[..., 2]], axis=-1)
    targets = _lock_and_lift(skeleton, legs, flat - quat.rotate(new_rot, soles), new_rot, floor, normal, locks, dt, w)
    shift = np.clip(np.min(targets[..., 1] - ankles[..., 1], axis=1), -max_pelvis_shift, max_pelvis_shift)
    offs = np.broadcast_to(off, rotations.shape[:-2] + off.shape[-2:])
    lengths = np.stack(
        [np.linalg.norm(offs[..., lo, :], axis=-1) + np.linalg.norm(offs[..., f, :], axis=-1) for _, lo, f in idx],
        axis=-1,
    )
    shift = _reach_shift(np.stack(hip, axis=1), targets, lengths, shift, max_pelvis_shift)
    roots[:, 1] += shift
    hips = {int(skeleton.parents[u]) for u, _, _ in idx}
    if len(hips) != 1:  # legs hung from different joints: one solve per leg
        pose = Pose(roots, rotations)
        for k, ((u, lo, f), leg) in enumerate(zip(idx, legs, strict=True)):
            wp, wr = path_fk(skeleton, roots, rotations, lo, off)
            pole = wp[lo] + quat.rotate(wr[int(skeleton.parents[u])], leg.knee_forward)
            two_bone_ik(skeleton, pose, (u, lo, f), targets[:, k], pole, end_rotation=new_rot[:, k], offsets=off)
        return shift
    _solve_legs(skeleton, roots, rotations, off, hips.pop(), idx, legs, targets, new_rot)
    return shift


def _ground_compiled(
    skeleton: Skeleton,
    roots: F,
    rotations: F,
    ground: GroundQuery,
    legs: tuple[Leg, ...],
    off: F,
    idx: list[tuple[int, int, int]],
    align_height: float,
    contact_height: float,
    max_pelvis_shift: float,
    w: F,
    locks: Sequence[FootLock | None] | None,
    dt: float,
    lock_columns: Columns | None = None,
) -> F:
    """:func:`ground_feet_batch` on the compiled kernels (:mod:`engine.ik._ground_kernel`); the locks in numpy."""
    p, n = rotations.shape[0], len(legs)
    given_roots, given_rotations = roots, rotations  # the kernels write C-contiguous doubles; copied back below
    roots = np.ascontiguousarray(roots, dtype=np.float64)
    rotations = np.ascontiguousarray(rotations, dtype=np.float64)
    offs = kernel_array(off, rotations.shape[:-1] + (3,))
    leg_idx = np.array(idx, dtype=np.int64).reshape(n, 3)
    soles = np.array([leg.sole for leg in legs], dtype=np.float64).reshape(n, 3)
    tips = np.array([skeleton.tips[f] for _, _, f in idx], dtype=np.float64).reshape(n, 3)
    heels = np.array([leg.heel for leg in legs], dtype=np.float64).reshape(n, 3)
    knees = np.array([leg.knee_forward for leg in legs], dtype=np.float64).reshape(n, 3)
    ankles, hips, sole, qfeet = np.empty((p, n, 3)), np.empty((p, n, 3)), np.empty((p, n, 3)), np.empty((p, n, 4))
    _kernel.legs_fk(skeleton.parents, np.arange(p), roots, rotations, offs, leg_idx, soles, ankles, qfeet, hips, sole)
    height, normal = ground(sole[..., 0], sole[..., 2])
    height, normal = kernel_array(height, (p, n)), kernel_array(normal, (p, n, 3))
    if not (np.all(np.isfinite(height)) and np.all(np.isfinite(normal))):
        raise ValueError("ground query returned non-finite values")
    targets, new_rot, floor = np.empty((p, n, 3)), np.empty((p, n, 4)), np.empty((p, n, 3))
    _kernel.legs_targets(
        sole,
        qfeet,
        height,
        normal,
        np.ascontiguousarray(w),
        soles,
        tips,
        heels,
        align_height,
        contact_height,
        targets,
        new_rot,
        floor,
    )
    if locks is not None:
        toes = targets + quat.rotate(new_rot, tips)
        _apply_locks(locks, targets, new_rot, toes, floor, tips, dt, lock_columns)
    shift = np.empty(p)
    _kernel.legs_solve(
        skeleton.parents,
        roots,
        rotations,
        offs,
        leg_idx,
        knees,
        targets,
        new_rot,
        ankles,
        hips,
        max_pelvis_shift,
        shift,
    )
    if roots is not given_roots:
        given_roots[...] = roots
    if rotations is not given_rotations:
        given_rotations[...] = rotations
    return shift


def _solve_legs(
    skeleton: Skeleton,
    roots: F,
    rotations: F,
    off: F,
    hip: int,
    idx: list[tuple[int, int, int]],
    legs: tuple[Leg, ...],
    targets: F,
    new_rot: F,
) -> None:
    """Every leg of every puppet in one batched two-bone solve.

    The legs hang from one joint, so each is a chain ``hip → upper → lower → foot`` of its
    own: a four-joint skeleton whose root is the hip's world transform, batched ``[L, P]``.
    Its forward kinematics repeats the full skeleton's operations along the same path, so
    the result is the one a solve per leg gives.
    """
    from engine.ik.two_bone import two_bone_ik

    wp, wr = path_fk(skeleton, roots, rotations, hip, off)
    chains = np.array(idx).T  # [3, L]
    offs = np.broadcast_to(off, rotations.shape[:-2] + off.shape[-2:])
    leg_off = np.zeros((len(legs),) + offs.shape[:-2] + (4, 3))
    leg_off[..., 1:, :] = np.moveaxis(offs[..., chains, :], -2, 0)  # [L, P, 3, 3]
    leg_rot = np.empty((len(legs),) + rotations.shape[:-2] + (4, 4))
    leg_rot[..., 0, :] = wr[hip]
    leg_rot[..., 1:, :] = np.moveaxis(rotations[..., chains, :], -2, 0)
    chain = Skeleton(("hip", "upper", "lower", "foot"), np.array([-1, 0, 1, 2]), leg_off.reshape(-1, 4, 3)[0])
    root = np.broadcast_to(wp[hip], leg_rot.shape[:-2] + (3,)).copy()
    pose = Pose(root, leg_rot)
    lp, lr = path_fk(chain, root, leg_rot, 2, leg_off)
    knee = np.array([leg.knee_forward for leg in legs])[:, None, :]
    pole = lp[2] + quat.rotate(lr[0], knee)
    two_bone_ik(
        chain,
        pose,
        (1, 2, 3),
        np.moveaxis(targets, 1, 0),
        pole,
        end_rotation=np.moveaxis(new_rot, 1, 0),
        offsets=leg_off,
    )
    rotations[..., chains, :] = np.moveaxis(leg_rot[..., 1:, :], 0, -2)
