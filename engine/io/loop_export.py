"""Loops made to land well in other tools: a whole number of frames at a nominal rate, and a closing frame.

An extracted loop lasts whatever its period is (1.1637 s), so writing it at "its own" rate
gives BVH frame times like 1/120.286 s, which Blender plays 1.2-5x slow unless the user
changes its import options. :func:`loop_at_rate` instead resamples the loop to the whole
number of frames nearest to its period at a nominal rate (the source's, or ``--fps``): the
loop stretches by under half a frame (its travel with it, so its speed is kept) and the
file's rate is the one users expect.
:func:`closed` repeats the first pose at the end (its root moved on by the cycle's travel),
which is what a Cycles modifier or an NLA repeat expects of a loop's last key.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from engine import quat
from engine.clip import Clip

__all__ = ["closed", "is_seamless", "loop_at_rate", "nominal_rate", "opened"]

_SEAMLESS = 0.05  # end-to-start pose gap, as a share of the pose's range, below which an animation is a loop


def nominal_rate(fps: float) -> float:
    """The rate a file means: ``Frame Time: 0.0333333`` is 30.00003 fps, which means 30."""
    whole = round(fps)
    return float(whole) if whole > 0 and abs(fps - whole) <= 1e-3 * fps else float(fps)


def closed(clip: Clip, travel: ArrayLike | None = None, turn: float = 0.0) -> Clip:
    """A non-looping clip of a loop with its first frame repeated at the end.

    The repeated root is moved on by ``travel`` (world, per cycle) and its rotation turned
    by ``turn`` radians about +Y, so a walk that travels or turns continues instead of
    jumping back."""
    if not clip.loop:
        raise ValueError(f"clip {clip.name!r} is not a loop")
    shift = np.zeros(3) if travel is None else np.asarray(travel, dtype=np.float64)[:3]
    root = np.concatenate([clip.root, clip.root[:1] + shift])
    first = clip.rotations[:1].copy()
    first[:, 0] = quat.mul(quat.from_axis_angle(np.array([0.0, 1.0, 0.0]), turn), first[:, 0])
    rot = np.concatenate([clip.rotations, first])
    tr = None if clip.translations is None else np.concatenate([clip.translations, clip.translations[:1]])
    sc = None if clip.scales is None else np.concatenate([clip.scales, clip.scales[:1]])
    return replace(clip, root=root, rotations=rot, loop=False, translations=tr, scales=sc, root_motion=None)


def is_seamless(clip: Clip) -> bool:
    """Whether a clip's last pose is its first (a game asset's cycle, or a closed loop :func:`closed` wrote)."""
    rot = clip.rotations
    span = float(np.ptp(rot, axis=0).max()) if clip.num_frames else 0.0
    return clip.num_frames >= 4 and span > 0 and float(np.abs(rot[-1] - rot[0]).max()) <= _SEAMLESS * span


def opened(clip: Clip) -> Clip:
    """The loop of a closed clip (see :func:`is_seamless`): its closing frame dropped, ``loop`` set."""
    if clip.loop or not is_seamless(clip):
        raise ValueError(f"clip {clip.name!r} is not a closed loop (its last pose is not its first)")
    n = clip.num_frames - 1
    tr = None if clip.translations is None else clip.translations[:n]
    sc = None if clip.scales is None else clip.scales[:n]
    return replace(
        clip, root=clip.root[:n], rotations=clip.rotations[:n], loop=True, translations=tr, scales=sc, root_motion=None
    )


def loop_at_rate(
    clip: Clip, rate: float, travel: ArrayLike | None = None, turn: float = 0.0
) -> tuple[Clip, NDArray[np.float64]]:
    """The loop resampled to ``n = round(duration · rate)`` frames played at exactly ``rate`` fps, and its travel.

    ``travel`` is the root's travel over one cycle (so the last-to-first segment moves on
    instead of jumping back). The loop's duration stretches by under half a frame; its
    travel stretches with it, so the loop keeps its speed (a 32.5-frame walk written as
    32 frames at 30 fps would otherwise walk 1.6 % faster) and the returned travel is the
    new loop's, for :func:`closed`.
    """
    if not rate > 0:
        raise ValueError(f"frame rate must be positive, got {rate}")
    shift = np.zeros(3) if travel is None else np.asarray(travel, dtype=np.float64)[:3]
    whole = closed(clip, shift, turn)
    n = max(int(round(clip.duration * rate)), 2)
    t = np.arange(n, dtype=np.float64) * (whole.duration / n)
    pose = whole.sample(t)
    stretch = n / rate / clip.duration - 1.0
    root = pose.root + np.outer(np.arange(n) / n, stretch * shift)
    out = replace(
        whole,
        fps=float(rate),
        root=root,
        rotations=pose.rotations,
        loop=True,
        translations=pose.offsets,
        scales=pose.scales,
    )
    return out, (1.0 + stretch) * shift
