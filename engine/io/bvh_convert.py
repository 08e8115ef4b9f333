"""BVH ⇄ engine clips: skeleton, quaternions and metres out of raw BVH channels, and back.

Real files disagree on conventions, and every rule here comes from one of them:

* **Position channels replace the OFFSET** (Bandai puts 6 channels on every joint and
  repeats the OFFSET in them). Adding the two would double every bone. Some exporters
  do add them, though: the iClone root of ``cmu_02_05_punch_ccbase.bvh`` has OFFSET
  y = 105.2 and a Yposition channel between -16 and +5.6, so replacing would sink the feet
  92 cm under the floor. ``positions="auto"`` (the default) decides per joint: replace
  when the channel's mean along the OFFSET's main axis is nearer the OFFSET than zero.
* **Each joint has its own rotation order**; angles compose intrinsically in the listed
  order (``from_euler("zxy", …)``), so ±180° Euler wraps vanish in the quaternions.
* **A static root above the moving hips** (Bandai's ``joint_Root``): a root whose single
  child has animated position channels is folded into that child (exact: the child's
  world transform is unchanged), so the travel lands on the clip's root.
* **Other joints' position channels that really move** (bones that stretch, props) become
  the clip's translation channel (:attr:`Clip.translations`); constant ones (Bandai repeats
  each OFFSET in them) are just the offset.
* **Units** differ (cm, inches, metres, CMU's ASF unit): with ``scale=None`` they are judged
  by the figure, see :mod:`engine.io.units`.
* **End Sites** become :attr:`Skeleton.tips`.

The clip keeps the file's axes (BVH is nearly always Y up); :mod:`engine.io.retarget`
re-orients when it maps onto the puppet.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from engine import quat
from engine.clip import Clip
from engine.io._tracks import fold_root
from engine.io.bvh import BvhError, BvhMotion, BvhWarning
from engine.io.units import judge_units
from engine.skeleton import Skeleton

__all__ = ["bvh_to_clip", "clip_to_bvh", "detect_unit_scale", "detect_tpose_frames", "skip_leading_tpose"]


def _replaces_offset(motion: BvhMotion, j: int, axes: list[int], cols: list[int]) -> bool:
    """Whether joint ``j``'s position channels are its translation (True) or added to its OFFSET."""
    off = motion.offsets[j]
    a = int(np.argmax(np.abs(off)))
    if abs(off[a]) < 1e-9 or a not in axes or motion.num_frames == 0:
        return True
    mean = float(np.mean(motion.data[:, cols[axes.index(a)]]))
    return abs(mean - off[a]) <= abs(mean)


def _local_tracks(
    motion: BvhMotion, positions: str = "auto"
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.bool_]]:
    """Per-frame local translations ``[F,J,3]`` and rotations ``[F,J,4]``, and which joints have positions."""
    if positions not in ("auto", "replace", "add"):
        raise ValueError(f"positions must be 'auto', 'replace' or 'add', got {positions!r}")
    f, j_count = motion.num_frames, motion.num_joints
    trans = np.broadcast_to(motion.offsets, (f, j_count, 3)).copy()
    rots = np.empty((f, j_count, 4))
    rots[...] = quat.IDENTITY
    has_pos = np.zeros(j_count, dtype=bool)
    starts = motion.channel_offsets()
    groups: dict[str, tuple[list[int], list[list[int]]]] = {}
    for j, chans in enumerate(motion.channels):
        rot_cols, order, pos_axes, pos_cols = [], "", [], []
        for k, c in enumerate(chans):
            col = int(starts[j]) + k
            if c.endswith("position"):
                pos_axes.append("xyz".index(c[0].lower()))
                pos_cols.append(col)
            else:
                rot_cols.append(col)
                order += c[0].lower()
        if pos_axes:
            has_pos[j] = True
            replace = positions == "replace" or (
                positions == "auto" and _replaces_offset(motion, j, pos_axes, pos_cols)
            )
            base = 0.0 if replace else motion.offsets[j, pos_axes]
            trans[:, j, pos_axes] = motion.data[:, pos_cols] + base
        if order:
            joints, cols = groups.setdefault(order, ([], []))
            joints.append(j)
            cols.append(rot_cols)
    for order, (joints, cols) in groups.items():
        rots[:, joints] = quat.from_euler(order, motion.data[:, np.array(cols)], degrees=True)
    return trans, rots, has_pos


def detect_unit_scale(skeleton: Skeleton) -> float:
    """Metres per file unit, judged by the figure (leg length of a human, else its extent)."""
    return judge_units(skeleton).scale


def bvh_to_clip(
    motion: BvhMotion,
    scale: float | None = None,
    skip_frames: int = 0,
    name: str | None = None,
    positions: str = "auto",
) -> Clip:
    """A clip of ``motion`` in metres (``scale`` = metres per file unit, auto-detected when ``None``).

    Args:
        motion: the raw BVH content.
        scale: metres per file unit; ``None`` detects it from the figure's size.
        skip_frames: leading frames to drop (see :func:`detect_tpose_frames`).
        name: clip name; defaults to the file's stem.
        positions: ``"replace"`` (BVH convention: position channels are the translation),
            ``"add"`` (added to the OFFSET) or ``"auto"`` (decided per joint, see above).
    """
    if not 0 <= skip_frames < motion.num_frames:
        raise BvhError(f"{motion.source or 'BVH'}: cannot skip {skip_frames} of {motion.num_frames} frames")
    motion = motion.with_frames(slice(skip_frames, None))
    trans, rots, has_pos = _local_tracks(motion, positions)
    tips = np.zeros((motion.num_joints, 3))
    for j, tip in motion.end_sites.items():
        tips[j] = tip
    moves = has_pos & (np.ptp(trans, axis=0).max(axis=1) > 1e-9 * max(1.0, float(np.abs(trans).max())))
    names, parents, trans, rots, moves, tips = fold_root(
        list(motion.names), motion.parents.copy(), trans, rots, moves, tips
    )
    # Non-root joints keep one offset: the mean of their (normally constant) position channels.
    offsets = trans.mean(axis=0)
    offsets[0] = trans[0, 0]  # the root's rest position: where the clip starts
    skeleton = Skeleton(tuple(names), parents, offsets, tips)
    unit = detect_unit_scale(skeleton) if scale is None else float(scale)
    if not unit > 0:
        raise BvhError(f"{motion.source or 'BVH'}: scale must be positive, got {scale}")
    skeleton = Skeleton(skeleton.names, skeleton.parents, offsets * unit, tips * unit)
    clip_name = name if name is not None else (Path(motion.source).stem if motion.source else "bvh")
    translations = trans * unit if moves[1:].any() else None
    return Clip(clip_name, skeleton, motion.fps, trans[:, 0] * unit, rots, translations=translations)


def _dfs_order(parents: NDArray[np.int64]) -> list[int]:
    order: list[int] = []
    stack = [0]
    while stack:
        j = stack.pop()
        order.append(j)
        stack.extend(reversed(np.nonzero(parents == j)[0].tolist()))
    return order


def clip_to_bvh(clip: Clip, order: str = "ZXY", unit: float = 100.0) -> BvhMotion:
    """A BVH of ``clip``: root ``X/Y/Zposition`` + rotations, other joints rotations in ``order``.

    ``unit`` is file units per metre (100: centimetres, what most tools expect). Euler angles
    are unwrapped over time so curve editors see continuous channels. Joints whose
    translation channel moves get position channels too; every leaf keeps an End Site (a
    zero one when the bone has no tip), as importers expect. BVH has no scale: a clip's
    scale channel is dropped with a :class:`~engine.io.bvh.BvhWarning`.
    """
    order = order.upper()
    if sorted(order) != ["X", "Y", "Z"]:
        raise ValueError(f"rotation order must be a permutation of XYZ, got {order!r}")
    if clip.scales is not None:
        warnings.warn(
            BvhWarning(f"clip {clip.name!r}: BVH has no scale channels; the clip's scale is dropped"), stacklevel=2
        )
    sk = clip.skeleton
    perm = _dfs_order(sk.parents)
    inv = np.empty(len(perm), dtype=np.int64)
    inv[perm] = np.arange(len(perm))
    parents = np.array([-1 if sk.parents[j] < 0 else inv[sk.parents[j]] for j in perm], dtype=np.int64)
    rot_chans = tuple(f"{a}rotation" for a in order)
    pos_chans = ("Xposition", "Yposition", "Zposition")
    trans = clip.translations
    moving = np.zeros(sk.num_joints, dtype=bool)
    if trans is not None:
        moving[1:] = np.ptp(trans[:, 1:], axis=0).max(axis=1) > 1e-9
    channels = tuple((pos_chans + rot_chans) if k == 0 or moving[j] else rot_chans for k, j in enumerate(perm))
    angles = quat.to_euler(order.lower(), clip.rotations[:, perm], degrees=True)  # [F,J,3]
    if clip.num_frames > 1:
        angles = np.unwrap(angles, period=360.0, axis=0)
    columns = []
    for k, j in enumerate(perm):
        if k == 0:
            columns.append(clip.root * unit)
        elif trans is not None and moving[j]:  # moving[j] only where trans exists
            columns.append(trans[:, j] * unit)
        columns.append(angles[:, k])
    data = np.concatenate(columns, axis=1)
    leaves = {j for j in range(sk.num_joints) if not sk.children(j)}
    end_sites = {k: sk.tips[j] * unit for k, j in enumerate(perm) if j in leaves or np.any(sk.tips[j])}
    offsets = sk.offsets[perm] * unit
    offsets[0] = 0.0  # the root's position channels say where it is; a zero OFFSET leaves no doubt
    return BvhMotion(
        tuple(sk.names[j] for j in perm), parents, offsets, end_sites, channels, 1.0 / clip.fps, data, clip.name
    )


def detect_tpose_frames(motion: BvhMotion, max_lead: int = 30) -> int:
    """Number of leading frames that are a T-pose lead-in (0 if there is none).

    The CMU "DAZ-friendly" conversions start with the rest T-pose at frame 0 and ramp into
    the first real pose over the next frames (about 20-25° per frame on the shoulders).
    Frame 0 counts as such a lead-in when at least half of the non-root rotation channels are
    zero there and no later frame comes back near it; the ramp then lasts while the
    frame-to-frame change stays above a quarter of the first ramp step.
    """
    f = motion.num_frames
    if f < 12:
        return 0
    rot = motion.rotation_columns()
    rot[: motion.channel_offsets()[1]] = False  # the root's heading is not pose
    if not rot.any():
        return 0
    angles = np.unwrap(motion.data[:, rot], period=360.0, axis=0)
    if np.mean(np.abs(motion.data[0, rot]) < 0.5) < 0.5:
        return 0
    dist = np.sqrt(np.mean(((angles - angles[0] + 180.0) % 360.0 - 180.0) ** 2, axis=1))
    if dist[10:].min() < 0.5 * np.median(dist):
        return 0
    steps = np.sqrt(np.mean(np.diff(angles, axis=0) ** 2, axis=1))
    lead = 1
    while lead < min(max_lead, f - 1) and steps[lead] > 0.25 * steps[0]:
        lead += 1
    return lead


def skip_leading_tpose(motion: BvhMotion) -> BvhMotion:
    """``motion`` without its T-pose lead-in (unchanged when it has none)."""
    lead = detect_tpose_frames(motion)
    return motion.with_frames(slice(lead, None)) if lead else motion
