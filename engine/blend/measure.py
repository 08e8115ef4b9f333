"""Measuring what a blend actually does: play it step by step and record the motion.

The lookup table must not *assume* a probe's speed from its parameters (the thesis
stresses the mapping is non-linear); it plays the blend the way the runtime does —
fixed steps, the shared phase advancing by ``dt / Σ wᵢTᵢ``, root motion accumulated
per step and turned by the accumulated heading — and measures the result. The same
player drives the benchmark's foot-sliding figure, so the runtime, the table and the
bench agree on what "playing" means.

Everything is batched over probes: ``[P, K]`` weights play in one loop over steps.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from engine import quat
from engine.blend.space import BlendSpace
from engine.fk import forward_kinematics, world_points

__all__ = [
    "Playback",
    "play",
    "measure_locomotion",
    "foot_slide",
    "blended_contacts",
    "contact_votes",
    "LOCOMOTION_PROPERTIES",
]

from engine.arrays import F64 as F

LOCOMOTION_PROPERTIES: tuple[str, ...] = ("speed", "height")
_UP = np.array([0.0, 1.0, 0.0])


@dataclass(frozen=True)
class Playback:
    """A played blend, per step ``t`` and batch element ``b``.

    Attributes:
        position: ``[T, B, 3]`` ground position of the character (root motion integrated).
        heading: ``[T, B]`` heading about +Y in radians.
        root: ``[T, B, 3]`` world root (hips) position.
        rotations: ``[T, B, J, 4]`` local rotations, joint 0 including the heading.
        phase: ``[T, B]`` the shared (unwrapped) phase of each step.
        dt: seconds per step.
    """

    position: F
    heading: F
    root: F
    rotations: F
    phase: F
    dt: float


def play(
    space: BlendSpace,
    weights: ArrayLike,
    steps: int,
    dt: float,
    rate: ArrayLike = 1.0,
    phase: ArrayLike = 0.0,
    carried: ArrayLike | None = None,
) -> Playback:
    """Play the blends ``weights [B, K]`` for ``steps`` fixed steps of ``dt`` at playback ``rate``.

    ``carried [B, 3]`` (m/s, character frame) moves the character at that velocity
    instead of by the blend's root motion — a puppet dragged by the MotionStick at
    the requested speed — so feet slide exactly as much as the blend's speed is off.
    """
    w = np.atleast_2d(np.asarray(weights, dtype=np.float64))
    b = len(w)
    ph = np.broadcast_to(np.asarray(phase, dtype=np.float64), (b,)).copy()
    pos = np.zeros((b, 3))
    head = np.zeros(b)
    positions = np.empty((steps, b, 3))
    headings = np.empty((steps, b))
    roots = np.empty((steps, b, 3))
    rots = np.empty((steps, b, space.clips[0].skeleton.num_joints, 4))
    phases = np.empty((steps, b))
    for s in range(steps):
        phases[s] = ph
        pose = space.sample(w, ph)
        hq = quat.from_axis_angle(_UP, head)
        positions[s], headings[s] = pos, head
        roots[s] = pos + quat.rotate(hq, pose.root)
        r = pose.rotations.copy()
        r[:, 0] = quat.mul(hq, r[:, 0])
        rots[s] = r
        ph, travel, turn = space.advance(ph, w, dt, rate)
        if carried is not None:
            travel = np.broadcast_to(np.asarray(carried, dtype=np.float64), (b, 3)) * dt
        pos = pos + quat.rotate(hq, travel)
        head = head + turn
    return Playback(positions, headings, roots, rots, phases, dt)


def measure_locomotion(space: BlendSpace, probes: ArrayLike, dt: float = 1.0 / 60.0) -> F:
    """Measured ``(root speed m/s, hips height m)`` ``[P, 2]`` of the blends at ``probes [P, N]``.

    Each probe plays one whole blended cycle in steps of ``dt``; the last step is
    shortened so the measurement covers exactly one cycle (a gait's speed varies
    within a stride, so a partial cycle would bias it). Speed is the ground
    displacement over the cycle divided by its duration; height is the mean height
    of the root over the cycle.
    """
    w = space.weights(np.asarray(probes, dtype=np.float64))
    b = len(w)
    period = space.cycle_duration(w)
    ph = np.zeros(b)
    pos = np.zeros((b, 3))
    head = np.zeros(b)
    elapsed = np.zeros(b)
    height_sum = np.zeros(b)
    while np.any(elapsed < period - 1e-12):
        step = np.clip(period - elapsed, 0.0, dt)
        height_sum += space.sample_root(w, ph)[:, 1] * step
        new_ph = ph + step / period
        travel, turn = space.sync.root_delta(ph, new_ph, w)
        pos += quat.rotate(quat.from_axis_angle(_UP, head), travel)
        head += turn
        ph, elapsed = new_ph, elapsed + step
    speed = np.linalg.norm(pos[:, [0, 2]], axis=-1) / period
    return np.stack([speed, height_sum / period], axis=-1)


def contact_votes(space: BlendSpace, weights: ArrayLike, phase: ArrayLike, tracks: Sequence[ArrayLike]) -> F:
    """How much of a blend's weight plants each foot: ``[..., F]`` in ``[0, 1]``.

    ``tracks[k]`` is clip ``k``'s per-frame contact labels ``[frames, F]`` (e.g.
    ``engine.clips.foot_contacts``); each is read at the clip's synced frame and
    weighted by the blend weights.
    """
    w = np.asarray(weights, dtype=np.float64)
    times = space.sync.clip_times(phase)
    votes = np.zeros(w.shape[:-1] + (np.asarray(tracks[0]).shape[-1],))
    for k, (clip, track) in enumerate(zip(space.clips, tracks, strict=True)):
        labels = np.asarray(track, dtype=bool)
        frame = np.round(times[..., k] * clip.fps).astype(np.int64) % clip.num_frames
        votes = votes + w[..., k, None] * labels[frame]
    return votes


def blended_contacts(
    space: BlendSpace, weights: ArrayLike, phase: ArrayLike, tracks: Sequence[ArrayLike]
) -> NDArray[np.bool_]:
    """Contacts ``[..., F]`` of a blend: a foot is planted when clips holding most of the weight
    plant it (a strict majority of :func:`contact_votes`)."""
    return contact_votes(space, weights, phase, tracks) > 0.5


def foot_slide(
    space: BlendSpace,
    pb: Playback,
    feet: tuple[str, ...] = ("l_foot", "r_foot"),
    contacts: ArrayLike | None = None,
    contact_height: float = 0.03,
) -> F:
    """Mean horizontal speed ``[B]`` (m/s) of the feet's tips while they are in contact.

    A foot is in contact while its tip is within ``contact_height`` of its lowest
    point in the playback and, when ``contacts [T, B, F]`` labels are given (see
    :func:`blended_contacts`), the labels also say so: near a 50/50 blend of a walk
    (62 % stance) and a run (38 %) the vote alone would call a swing foot 12 cm up
    "planted", which is not what anyone sees as sliding. Speed is measured between
    consecutive steps where the foot is in contact at both.
    """
    sk = space.clips[0].skeleton
    idx = [sk.index(f) for f in feet]
    wpos, wrot = forward_kinematics(sk, pb.root, pb.rotations)
    tips = world_points(sk, wpos, wrot)[:, :, idx]  # [T, B, F, 3]
    low = tips[..., 1].min(axis=0, keepdims=True)
    contact = tips[..., 1] <= low + contact_height
    if contacts is not None:
        contact = contact & np.asarray(contacts, dtype=bool)
    both = contact[1:] & contact[:-1]
    vel = np.linalg.norm(np.diff(tips[..., [0, 2]], axis=0), axis=-1) / pb.dt
    total = np.where(both, vel, 0.0).sum(axis=(0, 2))
    count = both.sum(axis=(0, 2))
    return total / np.maximum(count, 1)
