"""Key operations of the key-pose workflow (thesis §4.2.5, §4.3.1): new clips, add, delete, move and pose keys.

The thesis' animator blocks a motion with a few key poses, posed with the static IK,
then shapes the in-betweens with Motion Curves (:mod:`.solver`). These are the key
edits, as pure functions from one :class:`~engine.keyframes.KeyframedClip` to another:

- :func:`rest_clip` — a new clip holding the skeleton's rest pose (a loop's seam is a key);
- :func:`insert_key` — a key at any time *without changing the motion*: every channel's
  Bézier segment is split at its own curve parameter (de Casteljau), so the baked clip
  is the same to rounding;
- :func:`delete_key` — the two segments become one, keeping the outer tangents
  (their time components still fit the wider spacing);
- :func:`move_key` — a key slides between its neighbours; the time components of the
  tangents of both segments scale with their spacings, so easing keeps its shape;
- :func:`set_key_channels` — a key takes a new pose; the tangents at it and its
  neighbours become Catmull-Rom (a freshly posed key, as in a blocking pass: shape the
  in-betweens with drags after posing). A loop's seam key is the first and the last key.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from engine import quat
from engine.keyframes import BezierCurves, KeyframedClip
from engine.skeleton import Skeleton

__all__ = [
    "rest_clip",
    "insert_key",
    "delete_key",
    "move_key",
    "set_key_channels",
    "pose_channels",
    "key_frames",
    "MIN_KEY_GAP_FRAMES",
]

from engine.arrays import F64 as F

MIN_KEY_GAP_FRAMES = 2


def key_frames(clip: KeyframedClip) -> NDArray[np.int64]:
    """The frame of each key (rounded from its time)."""
    t = clip.curves.times
    return np.rint((t - t[0]) * clip.fps).astype(np.int64)


def pose_channels(root: ArrayLike, rotations: ArrayLike, near: ArrayLike | None = None) -> F:
    """``[C]`` channels of a pose; rotation vectors on the side of ``near`` (a key's old channels) to avoid flips."""
    rot = quat.normalize(np.asarray(rotations, dtype=np.float64))
    if near is not None:
        ref = quat.exp(np.asarray(near, dtype=np.float64)[3:].reshape(-1, 3))
        rot = quat.align_hemisphere(rot, ref)
    rv = quat.log(rot)
    if near is not None:  # log gives the short way (|θ| ≤ π); take the equivalent vector nearest the old one
        old = np.asarray(near, dtype=np.float64)[3:].reshape(-1, 3)
        ang = np.linalg.norm(rv, axis=-1, keepdims=True)
        axis = np.where(ang > 1e-12, rv / np.maximum(ang, 1e-12), 0.0)
        alt = rv - axis * 2.0 * np.pi
        use_alt = (ang > 1e-12) & (np.linalg.norm(alt - old, axis=-1, keepdims=True)
                                   < np.linalg.norm(rv - old, axis=-1, keepdims=True))  # fmt: skip
        rv = np.where(use_alt, alt, rv)
    return np.concatenate([np.asarray(root, dtype=np.float64).reshape(3), rv.reshape(-1)])


def rest_clip(skeleton: Skeleton, name: str = "keyposes", duration: float = 1.0, fps: float = 60.0,
              loop: bool = True, root: ArrayLike | None = None) -> KeyframedClip:  # fmt: skip
    """A new clip of two keys ``duration`` apart, both the rest pose (standing at ``root``, default the skeleton's)."""
    if not duration * fps >= 2 * MIN_KEY_GAP_FRAMES:
        raise ValueError(f"a new clip needs at least {2 * MIN_KEY_GAP_FRAMES} frames")
    start = np.zeros(3) if root is None else np.asarray(root, dtype=np.float64).reshape(3)
    c = np.concatenate([start, np.zeros(3 * skeleton.num_joints)])
    values = np.stack([c, c])
    gap = np.full_like(values, duration / 3.0)
    zero = np.zeros_like(values)
    curves = BezierCurves(np.array([0.0, duration]), values, gap, zero, gap.copy(), zero.copy())
    return KeyframedClip(name, skeleton, curves, float(fps), bool(loop))


def _arrays(c: BezierCurves) -> dict[str, F]:
    return {k: np.array(getattr(c, k)) for k in ("values", "out_x", "out_y", "in_x", "in_y")}


def insert_key(clip: KeyframedClip, time: float) -> KeyframedClip:
    """``clip`` with a key at ``time`` (strictly between two keys): the same motion, one more key."""
    c = clip.curves
    t = float(time)
    k = int(c.segment_of(t))
    t0, t1 = float(c.times[k]), float(c.times[k + 1])
    min_gap = MIN_KEY_GAP_FRAMES / clip.fps - 1e-9
    if not (t - t0 >= min_gap and t1 - t >= min_gap):
        raise ValueError(f"a key needs {MIN_KEY_GAP_FRAMES} frames to its neighbours (keys at "
                         f"{t0 * clip.fps:.0f} and {t1 * clip.fps:.0f})")  # fmt: skip
    _, lam = c.parameter(np.array([t]))
    lam = lam[0]  # [C] each channel's own parameter at ``t``
    # Control points per channel (x relative to t0): P0, P1, P2, P3.
    x0, x1, x2, x3 = 0.0, c.out_x[k], (t1 - t0) - c.in_x[k + 1], t1 - t0
    y0, y1, y2, y3 = c.values[k], c.values[k] + c.out_y[k], c.values[k + 1] - c.in_y[k + 1], c.values[k + 1]

    def lerp(a: Any, b: Any) -> Any:  # scalars or arrays alike (de Casteljau on values and on times)
        return a + (b - a) * lam

    x01, x12, x23 = lerp(x0, x1), lerp(x1, x2), lerp(x2, x3)
    y01, y12, y23 = lerp(y0, y1), lerp(y1, y2), lerp(y2, y3)
    x012, x123, y012, y123 = lerp(x01, x12), lerp(x12, x23), lerp(y01, y12), lerp(y12, y23)
    xm, ym = lerp(x012, x123), lerp(y012, y123)
    a = _arrays(c)
    row = {"values": ym, "in_x": xm - x012, "in_y": ym - y012, "out_x": x123 - xm, "out_y": y123 - ym}
    a["out_x"][k], a["out_y"][k] = x01 - x0, y01 - y0
    a["in_x"][k + 1], a["in_y"][k + 1] = x3 - x23, y3 - y23
    new = {name: np.insert(arr, k + 1, row[name], axis=0) for name, arr in a.items()}
    gaps = np.diff(np.insert(c.times, k + 1, t))[:, None]
    # Rounding can leave a time component a hair outside [0, spacing] (Eq. 4.7): clamp it back.
    new["out_x"][:-1] = np.clip(new["out_x"][:-1], 0.0, gaps)
    new["in_x"][1:] = np.clip(new["in_x"][1:], 0.0, gaps)
    times = np.insert(c.times, k + 1, t)
    return replace(clip, curves=BezierCurves(times, **new))


def _is_seam(clip: KeyframedClip, k: int) -> bool:
    return k == 0 or k == clip.curves.times.size - 1


def delete_key(clip: KeyframedClip, k: int) -> KeyframedClip:
    """``clip`` without key ``k`` (not the first or last key: they bound the clip, a loop's seam)."""
    c = clip.curves
    n = c.times.size
    if not 0 <= k < n:
        raise ValueError(f"there is no key {k} (keys 0…{n - 1})")
    if _is_seam(clip, k):
        raise ValueError("the first and last keys bound the clip and cannot be deleted")
    a = {name: np.delete(arr, k, axis=0) for name, arr in _arrays(c).items()}
    a["out_x"][k - 1] = c.out_x[k - 1]  # kept: the merged segment is wider, so they still fit
    a["in_x"][k] = c.in_x[k + 1]
    return replace(clip, curves=BezierCurves(np.delete(c.times, k), **a))


def move_key(clip: KeyframedClip, k: int, time: float) -> KeyframedClip:
    """``clip`` with key ``k`` at ``time`` (between its neighbours, not the bounding keys)."""
    c = clip.curves
    n = c.times.size
    if not 0 <= k < n:
        raise ValueError(f"there is no key {k} (keys 0…{n - 1})")
    if _is_seam(clip, k):
        raise ValueError("the first and last keys bound the clip and cannot move")
    t = float(time)
    min_gap = MIN_KEY_GAP_FRAMES / clip.fps - 1e-9
    if not (t - c.times[k - 1] >= min_gap and c.times[k + 1] - t >= min_gap):
        raise ValueError(f"a key stays {MIN_KEY_GAP_FRAMES} frames from its neighbours")
    a = _arrays(c)
    times = np.array(c.times)
    old_l, old_r = times[k] - times[k - 1], times[k + 1] - times[k]
    times[k] = t
    sl, sr = (t - times[k - 1]) / old_l, (times[k + 1] - t) / old_r
    a["out_x"][k - 1] *= sl
    a["in_x"][k] *= sl
    a["out_x"][k] *= sr
    a["in_x"][k + 1] *= sr
    return replace(clip, curves=BezierCurves(times, **a))


def _catmull_rom(times: F, values: F, loop: bool, k: int) -> F:
    """``[C]`` the Catmull-Rom slope (value per second) at key ``k``."""
    n = times.size
    if loop:
        period = times[-1] - times[0]
        last = n - 1  # key ``last`` is key 0 a period later
        i = k % last
        prev_t, prev_v = (times[i - 1], values[i - 1]) if i > 0 else (times[last - 1] - period, values[last - 1])
        next_t, next_v = times[i + 1], values[i + 1]
        return (next_v - prev_v) / (next_t - prev_t)
    if k == 0:
        return (values[1] - values[0]) / (times[1] - times[0])
    if k == n - 1:
        return (values[-1] - values[-2]) / (times[-1] - times[-2])
    return (values[k + 1] - values[k - 1]) / (times[k + 1] - times[k - 1])


def set_key_channels(clip: KeyframedClip, k: int, channels: ArrayLike) -> KeyframedClip:
    """``clip`` with key ``k`` set to ``channels``; Catmull-Rom tangents at ``k`` and its neighbours."""
    c = clip.curves
    n = c.times.size
    if not 0 <= k < n:
        raise ValueError(f"there is no key {k} (keys 0…{n - 1})")
    v = np.asarray(channels, dtype=np.float64).reshape(c.num_channels)
    if not np.isfinite(v).all():
        raise ValueError("a key pose must be finite")
    a = _arrays(c)
    seam = clip.loop and _is_seam(clip, k)
    a["values"][k] = v
    if seam:
        a["values"][0] = a["values"][-1] = v
    touched = {k - 1, k, k + 1}
    if seam:
        touched |= {0, 1, n - 2, n - 1}
    if clip.loop and touched & {0, n - 1}:
        touched |= {0, n - 1}  # a loop's seam is one key: both copies take the same tangents
    times = c.times
    for i in sorted(j for j in touched if 0 <= j < n):
        slope = _catmull_rom(times, a["values"], clip.loop, i)
        if i > 0:
            gap = times[i] - times[i - 1]
            a["in_x"][i], a["in_y"][i] = gap / 3.0, slope * gap / 3.0
        if i < n - 1:
            gap = times[i + 1] - times[i]
            a["out_x"][i], a["out_y"][i] = gap / 3.0, slope * gap / 3.0
    return replace(clip, curves=BezierCurves(times, **a))
