"""Planar contacts from one stroke (SCA 2017 §5.3, Figs. 5–6): project, unify, re-integrate.

1. A straight stroke extruded along the view direction is a plane (:func:`plane_from_stroke`).
2. The keypoints of each chosen item on the wrong side of it are projected onto it; those
   frames are the item's contacts (Fig. 5).
3. The contact velocities — relative to the root, i.e. in character space — of all items
   are unified by one closed cubic B-spline λ fitted by least squares (Fig. 6), lying in
   the plane. Where no item touches, a small curvature penalty carries λ across.
4. Each contact run is re-integrated with velocity λ (``p(t+dt) = p(t) + λ·dt``, centred on
   the projected run); the rest of the curve is scaled by ``s_l`` along the contact direction
   so it still joins the new ends; the root moves by ``−λ`` in the world. A contact point
   then moves by ``+λ`` relative to a root that moves by ``−λ``: it stays put, no sliding.

The clip's loop convention (engine.clip) extrapolates the closing root-motion step from
the mean step of the others, so λ is fitted with the one linear equality that makes its
last step equal that mean: the feet stay planted across the seam too.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from authoring.mocurves.spatial import set_positions
from engine import quat
from engine.clip import Clip, RootMotion
from engine.fk import forward_kinematics

__all__ = ["ContactPlane", "ContactResult", "plane_from_stroke", "contact_runs", "solve_contacts"]

from engine.arrays import F64 as F

_UP = np.array([0.0, 1.0, 0.0])


@dataclass(frozen=True)
class ContactPlane:
    """A plane through ``point`` whose ``normal`` points to the allowed side."""

    point: F
    normal: F

    def signed_distance(self, p: ArrayLike) -> F:
        """Distance of points ``[...,3]`` from the plane, negative on the wrong side."""
        return np.asarray(np.sum((np.asarray(p, dtype=np.float64) - self.point) * self.normal, axis=-1))

    def project(self, p: ArrayLike) -> F:
        """Points ``[...,3]`` moved along the normal onto the plane."""
        p = np.asarray(p, dtype=np.float64)
        return p - self.signed_distance(p)[..., None] * self.normal


def plane_from_stroke(a: ArrayLike, b: ArrayLike, view_dir: ArrayLike, allowed: ArrayLike) -> ContactPlane:
    """The plane holding stroke ``a → b`` (world points) and the view direction.

    Args:
        a, b: stroke ends in the world (unprojected at the depth of the curves).
        view_dir: the camera's viewing direction.
        allowed: a point on the allowed side (the character's root), which orients the normal.

    Raises:
        ValueError: a zero-length stroke, or one drawn along the view direction.
    """
    a, b, v = (np.asarray(x, dtype=np.float64) for x in (a, b, view_dir))
    n = np.cross(b - a, v)
    length = float(np.linalg.norm(n))
    if (
        not np.isfinite(length)
        or length < 1e-9 * max(float(np.linalg.norm(b - a) * np.linalg.norm(v)), 1e-12)
        or length == 0
    ):
        raise ValueError("contact stroke is too short or parallel to the view: draw a line across the curves")
    n = n / length
    if np.dot(np.asarray(allowed, dtype=np.float64) - a, n) < 0:
        n = -n
    return ContactPlane(a, n)


def contact_runs(mask: NDArray[np.bool_]) -> list[tuple[int, int]]:
    """Cyclic runs of ``True`` as ``(first, last)`` frame pairs (``last < first`` when a run wraps)."""
    m = np.asarray(mask, dtype=bool)
    n = len(m)
    if m.all():
        raise ValueError("an item touches the plane over the whole cycle; it could never leave the ground")
    if not m.any():
        return []
    start = int(np.flatnonzero(~m)[0])  # begin scanning just after a gap so no run is split
    runs, first = [], None
    for k in range(1, n + 1):
        f = (start + k) % n
        if m[f] and first is None:
            first = f
        if not m[f] and first is not None:
            runs.append((first, (f - 1) % n))
            first = None
    return runs


@dataclass(frozen=True)
class ContactResult:
    """A contact solve: the new clip, who touches when, λ and the stretch of each item.

    Attributes:
        clip: the edited clip (root motion replaced by ``−λ``).
        joints: the items considered.
        contacts: ``[F,I]`` whether item ``i`` touches the plane at frame ``f``.
        lam: ``[F,3]`` λ on each step ``f → f+1`` (m/s, character space).
        stretch: ``[I]`` ``s_l`` per item (1 where it has no contact).
    """

    clip: Clip
    joints: tuple[int, ...]
    contacts: NDArray[np.bool_]
    lam: F
    stretch: F


def _basis(phases: F, k: int) -> F:
    """Closed uniform cubic B-spline basis ``[len(phases), k]`` at phases in ``[0,1)``."""
    u = np.mod(phases, 1.0) * k
    seg = np.floor(u).astype(np.int64)
    s = u - seg
    w = np.stack([(1 - s) ** 3, 3 * s**3 - 6 * s**2 + 4, -3 * s**3 + 3 * s**2 + 3 * s + 1, s**3], axis=1) / 6.0
    b = np.zeros((len(phases), k))
    rows = np.arange(len(phases))
    for m in range(4):
        np.add.at(b, (rows, (seg + m - 1) % k), w[:, m])
    return b


def _fit_lambda(n: int, samples: list[tuple[int, F]], normal: F, segments: int, smooth: float) -> F:
    """λ on each step ``[n,3]``: least squares to the samples, in-plane, seam step = mean step."""
    k = max(4, min(segments, n))
    basis = _basis((np.arange(n) + 0.5) / n, k)  # λ at the step midpoints
    rows = np.array([s[0] for s in samples], dtype=np.int64)
    vals = np.array([s[1] for s in samples])
    a = basis[rows]
    d2 = np.roll(np.eye(k), -1, axis=1) - 2 * np.eye(k) + np.roll(np.eye(k), 1, axis=1)
    h = a.T @ a + smooth * len(rows) / k * d2.T @ d2
    g = a.T @ vals
    # Equality: λ_{n-1} = mean(λ_0 … λ_{n-2}) (the clip's closing-step convention).
    e = (basis[n - 1] - basis[: n - 1].mean(axis=0))[None]
    kkt = np.block([[h, e.T], [e, np.zeros((1, 1))]])
    sol = np.linalg.solve(kkt, np.vstack([g, np.zeros((1, 3))]))
    lam = basis @ sol[:k]
    return lam - np.outer(lam @ normal, normal)


def solve_contacts(clip: Clip, joints: Sequence[int], plane: ContactPlane, *,
                   segments: int = 12, smooth: float = 1e-3) -> ContactResult:  # fmt: skip
    """Apply a contact plane to items ``joints`` of the looping ``clip`` (see the module doc).

    Raises:
        ValueError: not a loop, no item reaches the plane, an item always in contact, or an
            item whose position cannot be edited.
    """
    if not clip.loop:
        raise ValueError(f"clip {clip.name!r} is not a loop; contacts are solved over a cycle")
    n, dt = clip.num_frames, 1.0 / clip.fps
    joints = tuple(int(j) for j in joints)
    pos, _ = forward_kinematics(clip.skeleton, clip.root, clip.rotations)
    curves = pos[:, joints]  # [F,I,3], character space
    contacts = plane.signed_distance(curves) <= 1e-9
    projected = np.where(contacts[..., None], plane.project(curves), curves)
    samples: list[tuple[int, F]] = []
    runs_of = []
    for i in range(len(joints)):
        runs = contact_runs(contacts[:, i])
        runs_of.append(runs)
        for first, last in runs:
            length = (last - first) % n
            for m in range(length):
                f = (first + m) % n
                samples.append((f, (projected[(f + 1) % n, i] - projected[f, i]) / dt))
    if not samples:
        raise ValueError("no item reaches the contact plane for two frames in a row; draw the stroke under the curves")
    lam = _fit_lambda(n, samples, plane.normal, segments, smooth)
    new = projected.copy()
    stretch = np.ones(len(joints))
    for i, runs in enumerate(runs_of):
        if not runs:
            continue
        ends = []
        for first, last in runs:
            frames = (first + np.arange((last - first) % n + 1)) % n
            steps = np.concatenate([[0.0 * lam[0]], np.cumsum(lam[frames[:-1]] * dt, axis=0)])
            seg = projected[frames, i].mean(axis=0) + steps - steps.mean(axis=0)
            new[frames, i] = seg
            ends.append((first, last, frames))
        direction = lam[np.flatnonzero(contacts[:, i])].mean(axis=0)
        direction = direction / max(float(np.linalg.norm(direction)), 1e-12)
        ratios = []
        for first, last, _ in ends:
            old = float(np.dot(projected[last, i] - projected[first, i], direction))
            nw = float(np.dot(new[last, i] - new[first, i], direction))
            ratios.append(nw / old if abs(old) > 1e-6 else 1.0)
        for r, (_, last, _) in enumerate(ends):
            nxt_first = ends[(r + 1) % len(ends)][0]
            _rescale_swing(new[:, i], projected[:, i], last, nxt_first, direction, ratios[r], n)
        stretch[i] = float(np.mean(ratios))
    edited = clip
    for i, j in enumerate(joints):
        if runs_of[i]:
            edited = set_positions(edited, j, new[:, i])
    heading = np.zeros(n) if clip.root_motion is None else clip.root_motion.heading
    mid = 0.5 * (heading + np.r_[heading[1:], heading[-1]])
    step = -quat.rotate(quat.from_axis_angle(_UP, mid), lam) * dt
    travel = np.vstack([np.zeros((1, 3)), np.cumsum(step[:-1], axis=0)])
    edited = replace(edited, root_motion=RootMotion(travel, heading.copy()))
    return ContactResult(edited, joints, contacts, lam, stretch)


def _rescale_swing(new: F, old: F, last: int, nxt: int, direction: F, s_l: float, n: int) -> None:
    """Scale the non-contact frames between runs by ``s_l`` along ``direction`` so they join the new ends."""
    gap = (nxt - last) % n or n
    if gap <= 1:
        return
    frames = (last + np.arange(gap + 1)) % n  # both run ends included
    c_old = 0.5 * (old[last] + old[nxt])
    c_new = 0.5 * (new[last] + new[nxt])
    rel = old[frames] - c_old
    scaled = c_new + rel + np.outer((s_l - 1.0) * (rel @ direction), direction)
    u = np.linspace(0.0, 1.0, gap + 1)[:, None]
    fix = (1 - u) * (new[last] - scaled[0]) + u * (new[nxt] - scaled[-1])
    new[frames[1:-1]] = (scaled + fix)[1:-1]
