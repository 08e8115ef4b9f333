"""Compiled blend-space playback for a crowd: weights, phase, root motion, pose and contact votes in one pass.

:func:`engine.blend.locomotion.animate` plays every puppet of a locomotion set through
:meth:`BlendSpace.weights`, :meth:`~BlendSpace.advance`, :meth:`~BlendSpace.sample` and
:func:`~engine.blend.measure.contact_votes`: some sixty numpy calls over ``[P, K, J, 4]``
arrays. With numba (:mod:`engine.jit`) the same formulas run as one loop over puppets
(:func:`play`), each skipping the clips it gives no weight, on the space's assets packed
once into flat arrays (:func:`packed`). The numpy methods stay as the twin and reference;
``tests/engine/blend/test_kernel.py`` plays a crowd on both and compares.

Spaces whose clips animate translations or scales take the numpy path (:func:`packed`
returns ``None``): their channels are blended there.

The one place the kernel is not the numpy path's arithmetic is the slerp between a clip's
frames (:func:`_arc_point`): its two sines are a Taylor polynomial on the short arcs a clip
has between frames (up to :data:`SERIES_UP_TO` rad; the humanoid's longest is 0.14), and the
common ``1/sin θ`` is left to the normalisation that follows. Each joint rotation differs from
the numpy slerp by at most :data:`SLERP_TOLERANCE` per component (tested); the sines were a
third of the kernel's time.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from engine.blend.space import BlendSpace
from engine.jit import njit, qarc, qmul, qnormalize

__all__ = ["SERIES_UP_TO", "SLERP_TOLERANCE", "Packed", "packed", "place", "play"]

from engine.arrays import F64 as F
from engine.arrays import I64 as I

SERIES_UP_TO = 0.3
"""rad: on arcs up to this long the slerp's sines are the series to ``x⁹`` (its remainder under ``x¹¹/11!``, a
relative error under ``1.5e-13`` at 0.3); a longer arc calls ``math.sin``."""
SLERP_TOLERANCE = 1e-12
"""How far (per quaternion component) a joint rotation of the kernel may be from :func:`engine.quat.slerp`'s."""


@dataclass(frozen=True)
class Packed:
    """A blend space's assets as flat arrays for :func:`play` (clip ``k``'s frames start at ``start[k]``)."""

    points: F  # [K, N]
    durations: F  # [K]
    fps: F  # [K]
    frames: I  # [K]
    start: I  # [K] first row of clip k in roots/rotations/votes; its root table starts at start[k] + k
    knot_x: F  # [K, M] phase knots
    knot_y: F  # [K, M] clip normalised times
    roots: F  # [ΣF, 3]
    rotations: F  # [ΣF, J, 4]
    tables: F  # [ΣF + K, 4] root motion tables (closing row appended)
    cycles: F  # [K, 4]
    contacts: F  # [ΣF, L] contact labels (0/1), L = 0 without feet
    arc_next: F  # [ΣF, J, 4] each row's next frame (cyclic) in the row's hemisphere
    arc_angle: F  # [ΣF, J] the angle between a row's rotation and its next frame's
    arc_sin: F  # [ΣF, J] its sine


_CACHE: dict[int, tuple[BlendSpace, Packed | None]] = {}


@njit
def _arcs(rotations: F, start: I, frames: I, arc_next: F, arc_angle: F, arc_sin: F) -> None:
    """:func:`~engine.jit.qarc` from every frame of every clip to its next (the last frame's next is the first):
    a crowd's slerps then cost two sines each instead of a dot, an arc cosine and three sines."""
    for k in range(start.shape[0]):
        n = frames[k]
        for i in range(n):
            r0, r1 = start[k] + i, start[k] + (i + 1) % n
            for j in range(rotations.shape[1]):
                b, theta, s = qarc(
                    (rotations[r0, j, 0], rotations[r0, j, 1], rotations[r0, j, 2], rotations[r0, j, 3]),
                    (rotations[r1, j, 0], rotations[r1, j, 1], rotations[r1, j, 2], rotations[r1, j, 3]),
                )
                for c in range(4):
                    arc_next[r0, j, c] = b[c]
                arc_angle[r0, j] = theta
                arc_sin[r0, j] = s


def packed(space: BlendSpace, tracks: list[NDArray[np.bool_]] | None) -> Packed | None:
    """The space's packed assets (cached per space and tracks), ``None`` when its clips have channels."""
    key = id(space)
    hit = _CACHE.get(key)
    if hit is not None and hit[0] is space and (hit[1] is None or (tracks is None) == (hit[1].contacts.shape[1] == 0)):
        return hit[1]
    clips = space.clips
    if any(c.translations is not None or c.scales is not None for c in clips):
        _CACHE[key] = (space, None)
        return None
    knots = space.sync._knots
    frames = np.array([c.num_frames for c in clips], dtype=np.int64)
    start = np.concatenate([[0], np.cumsum(frames)[:-1]]).astype(np.int64)
    rotations = np.ascontiguousarray(np.concatenate([c.rotations for c in clips]), dtype=np.float64)
    arc_next, arc_angle, arc_sin = (
        np.empty_like(rotations),
        np.empty(rotations.shape[:2]),
        np.empty(rotations.shape[:2]),
    )
    _arcs(rotations, start, frames, arc_next, arc_angle, arc_sin)
    result = Packed(
        points=np.ascontiguousarray(space.points, dtype=np.float64),
        durations=np.ascontiguousarray(space.sync.durations, dtype=np.float64),
        fps=np.array([c.fps for c in clips], dtype=np.float64),
        frames=frames,
        start=start,
        knot_x=np.stack([x for x, _ in knots]).astype(np.float64),
        knot_y=np.stack([y for _, y in knots]).astype(np.float64),
        roots=np.ascontiguousarray(np.concatenate([c.root for c in clips]), dtype=np.float64),
        rotations=rotations,
        tables=np.ascontiguousarray(np.concatenate([t for t, _ in space.sync._root_tables]), dtype=np.float64),
        cycles=np.stack([c for _, c in space.sync._root_tables]).astype(np.float64),
        contacts=(
            np.zeros((int(frames.sum()), 0))
            if tracks is None
            else np.concatenate([np.asarray(t, dtype=np.float64) for t in tracks])
        ),
        arc_next=arc_next,
        arc_angle=arc_angle,
        arc_sin=arc_sin,
    )
    _CACHE[key] = (space, result)
    return result


@njit
def _weights(points: F, q: F, out: F) -> None:
    """Gradient-band weights of one point (:func:`engine.blend.space.gradient_band_weights`)."""
    k, n = points.shape
    if k == 1:
        out[0] = 1.0
        return
    total = 0.0
    for i in range(k):
        h = math.inf
        for j in range(k):
            if j == i:
                continue
            dot, len2 = 0.0, 0.0
            for c in range(n):
                d = points[j, c] - points[i, c]
                dot += (q[c] - points[i, c]) * d
                len2 += d * d
            h = min(h, 1.0 - dot * (1.0 / len2))
        h = min(max(h, 0.0), 1.0)
        out[i] = h
        total += h
    for i in range(k):
        out[i] = out[i] / total


@njit
def _clip_time(pk_x: F, pk_y: F, duration: float, phase: float) -> float:
    """A clip's unwrapped time (s) at group ``phase`` (:meth:`SyncGroup.clip_times`)."""
    cycles = math.floor(phase)
    return (cycles + interp(phase - cycles, pk_x, pk_y)) * duration


@njit
def interp(x: float, xp: F, fp: F) -> float:
    """``np.interp`` of one value, as numba's ``np.interp`` computes it (numpy's C code, transcribed) but
    without the arrays that one allocates for its answer and its slopes on every call (a crowd's kernel
    calls it a dozen times per puppet). ``j`` is the last knot at or below ``x`` (what numpy's guessed
    binary search finds in a sorted ``xp``)."""
    n = xp.shape[0]
    if n == 1:
        return fp[0]
    if math.isnan(x):
        return x
    if x > xp[n - 1]:
        return fp[n - 1]
    if x < xp[0]:
        return fp[0]
    lo, hi = 0, n
    while lo < hi:
        mid = lo + ((hi - lo) >> 1)
        if x >= xp[mid]:
            lo = mid + 1
        else:
            hi = mid
    j = lo - 1
    if j == n - 1 or xp[j] == x:
        return fp[j]
    slope = (fp[j + 1] - fp[j]) / (xp[j + 1] - xp[j])
    out = slope * (x - xp[j]) + fp[j]
    if math.isnan(out):  # a nan one way: the other way (numpy ≥ 1.17)
        out = slope * (x - xp[j + 1]) + fp[j + 1]
        if math.isnan(out) and fp[j] == fp[j + 1]:
            out = fp[j]
    return out


@njit
def _root_row(tables: F, cycles: F, base: int, n: int, k: int, time: float, fps: float, out: F) -> None:
    """Accumulated root travel and heading ``out [4]`` at a clip time (:meth:`SyncGroup.root_motion`)."""
    f = time * fps
    cyc = math.floor(f / n)
    local = f - cyc * n
    i0 = min(math.floor(local), n - 1)
    a = local - i0
    for c in range(4):
        t0 = tables[base + i0, c]
        out[c] = t0 + a * (tables[base + i0 + 1, c] - t0) + cyc * cycles[k, c]


@njit
def play(
    pk_points: F,
    durations: F,
    fps: F,
    frames: I,
    start: I,
    knot_x: F,
    knot_y: F,
    roots: F,
    rotations: F,
    tables: F,
    cycles: F,
    contacts: F,
    arc_next: F,
    arc_angle: F,
    arc_sin: F,
    points: F,
    target: F,
    alpha: float,
    ease: bool,
    phase: F,
    rate: F,
    scale: F,
    feasible: F,
    dt: float,
    feasible_out: F,
    w_out: F,
    phase_out: F,
    wrapped: F,
    travel: F,
    turn: F,
    root_out: F,
    rot_out: F,
    votes: F,
) -> None:
    """Play ``dt`` seconds of every puppet: its blend point eased toward the lookup's ``target`` (in place in
    ``points [P,N]``, when ``ease``), the ``feasible`` request scaled to the puppet, then weights, new phase
    (and wrapped to ``[0, 1)``), root travel (clip frame, scaled) and turn, the blended pose at the new
    phase (root scaled) and the feet's votes. The easing and scalings are the numpy path's
    ``eased + alpha·(target − eased)`` and ``x·scale``, operation for operation."""
    k_all = pk_points.shape[0]
    joints = rotations.shape[1]
    legs = contacts.shape[1]
    dims = points.shape[1]
    row0, row1 = np.empty(4), np.empty(4)
    ref_rot = np.empty((joints, 4))
    for p in range(points.shape[0]):
        size = scale[p]
        if ease:
            for c in range(dims):
                points[p, c] = points[p, c] + alpha * (target[p, c] - points[p, c])
        for c in range(feasible.shape[1]):
            feasible_out[p, c] = feasible[p, c] * size
        w = w_out[p]
        _weights(pk_points, points[p], w)
        period = 0.0
        for k in range(k_all):
            period += w[k] * durations[k]
        ph0 = phase[p]
        ph1 = ph0 + dt * rate[p] / period
        phase_out[p] = ph1
        total, ref, best = 0.0, 0, -1.0
        for k in range(k_all):
            total += w[k]
            if w[k] > best:
                ref, best = k, w[k]
        for c in range(3):
            travel[p, c] = 0.0
            root_out[p, c] = 0.0
        turn[p] = 0.0
        for c in range(legs):
            votes[p, c] = 0.0
        for j in range(joints):
            for c in range(4):
                rot_out[p, j, c] = 0.0
        # every clip's joints are turned into the hemisphere of the heaviest clip's (blend_quaternions)
        t_ref = _clip_time(knot_x[ref], knot_y[ref], durations[ref], ph1)
        _frame_rotations(
            rotations,
            arc_next,
            arc_angle,
            arc_sin,
            start[ref],
            frames[ref],
            t_ref * fps[ref],
            ref_rot,
            ref_rot,
            False,
        )
        for k in range(k_all):
            if w[k] <= 0.0:  # no vote either: adding w·label = +0 to a sum of non-negative votes changes no bit
                continue
            n = frames[k]
            t1 = t_ref if k == ref else _clip_time(knot_x[k], knot_y[k], durations[k], ph1)
            if legs > 0:
                fr = int(np.rint(t1 * fps[k])) % n
                for c in range(legs):
                    votes[p, c] = votes[p, c] + w[k] * contacts[start[k] + fr, c]
            t0 = _clip_time(knot_x[k], knot_y[k], durations[k], ph0)
            _root_row(tables, cycles, start[k] + k, n, k, t0, fps[k], row0)
            _root_row(tables, cycles, start[k] + k, n, k, t1, fps[k], row1)
            for c in range(3):
                travel[p, c] += w[k] * (row1[c] - row0[c])
            turn[p] += w[k] * (row1[3] - row0[3])
            f = t1 * fps[k] % n
            i0 = math.floor(f) % n
            i1 = (i0 + 1) % n
            a = f - math.floor(f)
            wn = w[k] / total
            r0, r1 = start[k] + i0, start[k] + i1
            for c in range(3):
                root_out[p, c] += wn * (roots[r0, c] + a * (roots[r1, c] - roots[r0, c]))
            if k == ref:  # the heaviest clip's pose is ref_rot itself, already in its own hemisphere
                for j in range(joints):
                    for c in range(4):
                        rot_out[p, j, c] += wn * ref_rot[j, c]
                continue
            _frame_rotations(
                rotations, arc_next, arc_angle, arc_sin, start[k], n, t1 * fps[k], ref_rot, rot_out[p], True, wn
            )
        for c in range(3):
            root_out[p, c] = root_out[p, c] * size
            travel[p, c] = travel[p, c] * size
        wrapped[p] = ph1 % 1.0
        for j in range(joints):
            m = qnormalize((rot_out[p, j, 0], rot_out[p, j, 1], rot_out[p, j, 2], rot_out[p, j, 3]))
            rot_out[p, j, 0], rot_out[p, j, 1], rot_out[p, j, 2], rot_out[p, j, 3] = m


@njit
def _frame_rotations(
    rotations: F,
    arc_next: F,
    arc_angle: F,
    arc_sin: F,
    first: int,
    n: int,
    frame: float,
    ref: F,
    out: F,
    accumulate: bool,
    wn: float = 1.0,
) -> None:
    """A loop's joint rotations at fractional ``frame`` (slerp between its frames, :meth:`Clip.frame_pair`,
    on the arcs :func:`_arcs` measured): stored in ``out``, or (``accumulate``) turned into ``ref``'s
    hemisphere and added with weight ``wn``."""
    f = frame % n
    i0 = math.floor(f) % n
    a = f - math.floor(f)
    r0 = first + i0
    for j in range(rotations.shape[1]):
        q = _arc_point(
            (rotations[r0, j, 0], rotations[r0, j, 1], rotations[r0, j, 2], rotations[r0, j, 3]),
            (arc_next[r0, j, 0], arc_next[r0, j, 1], arc_next[r0, j, 2], arc_next[r0, j, 3]),
            arc_angle[r0, j],
            arc_sin[r0, j],
            a,
        )
        if not accumulate:
            for c in range(4):
                out[j, c] = q[c]
            continue
        if q[0] * ref[j, 0] + q[1] * ref[j, 1] + q[2] * ref[j, 2] + q[3] * ref[j, 3] < 0.0:
            q = (-q[0], -q[1], -q[2], -q[3])
        for c in range(4):
            out[j, c] += wn * q[c]


@njit
def _small_sin(x: float) -> float:
    """``sin x`` for ``0 ≤ x ≤`` :data:`SERIES_UP_TO` by its Taylor series to ``x⁹`` (Horner form)."""
    x2 = x * x
    return x * (1.0 - x2 / 6.0 * (1.0 - x2 / 20.0 * (1.0 - x2 / 42.0 * (1.0 - x2 / 72.0))))


@njit
def _arc_point(
    a: tuple[float, float, float, float], b: tuple[float, float, float, float], theta: float, s: float, t: float
) -> tuple[float, float, float, float]:
    """The point at ``t`` on the arc from ``a`` to ``b`` (angle ``theta``, its sine ``s``; :func:`~engine.jit.qarc`):
    :func:`~engine.jit.qslerp_arc` within :data:`SLERP_TOLERANCE`. The weights ``sin((1−t)θ)`` and ``sin(tθ)`` are
    not divided by ``sin θ``: the normalisation removes any common factor."""
    if s < 1e-6:
        wa, wb = 1.0 - t, t
    elif theta <= SERIES_UP_TO:
        wa, wb = _small_sin((1.0 - t) * theta), _small_sin(t * theta)
    else:
        wa, wb = math.sin((1.0 - t) * theta), math.sin(t * theta)
    return qnormalize((wa * a[0] + wb * b[0], wa * a[1] + wb * b[1], wa * a[2] + wb * b[2], wa * a[3] + wb * b[3]))


@njit
def place(rotation: F, positions: F, travel: F, turn: F, roots: F, rots: F, headings: F, world_roots: F) -> None:
    """Move every puppet by its travel and turn (both in its clip frame) and place its pose in the world:
    ``positions`` advanced in place, new ``headings``, the root in world space, the heading folded into
    joint 0 of ``rots`` (in place). The numpy twin is the end of :func:`engine.blend.locomotion._animate_group`;
    the operations are :mod:`engine.quat`'s in its order (an axis-angle about +Y keeps its zero products),
    so both agree bit for bit."""
    for p in range(rotation.shape[0]):
        w, x, y, z = rotation[p, 0], rotation[p, 1], rotation[p, 2], rotation[p, 3]
        yaw = math.atan2(2.0 * (x * z + w * y), 1.0 - 2.0 * (x * x + y * y))
        hq = _yaw_quat(yaw)
        step = _rotate(hq, (travel[p, 0], travel[p, 1], travel[p, 2]))
        turn_q = _yaw_quat(turn[p])
        hq_new = _yaw_quat(yaw + turn[p])
        r0 = qmul(hq_new, (rots[p, 0, 0], rots[p, 0, 1], rots[p, 0, 2], rots[p, 0, 3]))
        for c in range(4):
            rots[p, 0, c] = r0[c]
        offset = _rotate(hq_new, (roots[p, 0], roots[p, 1], roots[p, 2]))
        for c in range(3):
            positions[p, c] = positions[p, c] + step[c]
            world_roots[p, c] = positions[p, c] + offset[c]
        heading = qmul(turn_q, (w, x, y, z))
        n = math.sqrt(
            heading[0] * heading[0] + heading[1] * heading[1] + heading[2] * heading[2] + heading[3] * heading[3]
        )
        for c in range(4):
            headings[p, c] = heading[c] / n if n > 1e-12 else (1.0 if c == 0 else 0.0)


@njit
def _yaw_quat(angle: float) -> tuple[float, float, float, float]:
    """:func:`engine.quat.from_axis_angle` about +Y: ``(cos h, sin h·0, sin h·1, sin h·0)``, ``h = angle/2``."""
    half = 0.5 * angle
    s = math.sin(half)
    return (math.cos(half), s * 0.0, s * 1.0, s * 0.0)


@njit
def _rotate(q: tuple[float, float, float, float], v: tuple[float, float, float]) -> tuple[float, float, float]:
    """:func:`engine.quat.rotate`: ``v + w·t + u×t`` with ``t = 2·(u×v)``, in its order of operations."""
    ux, uy, uz = q[1], q[2], q[3]
    t0 = 2.0 * (uy * v[2] - uz * v[1])
    t1 = 2.0 * (uz * v[0] - ux * v[2])
    t2 = 2.0 * (ux * v[1] - uy * v[0])
    return (
        v[0] + q[0] * t0 + (uy * t2 - uz * t1),
        v[1] + q[0] * t1 + (uz * t0 - ux * t2),
        v[2] + q[0] * t2 + (ux * t1 - uy * t0),
    )
