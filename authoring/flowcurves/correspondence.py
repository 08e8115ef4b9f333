"""Automatic correspondence between SEcurves and a flow curve (§3.5.2, Eq. 3.10).

Every sample of an SEcurve (every ~4 px) whose closest flow-curve point is nearer than
``d_m = 100`` px and whose tangent is within ``θ_m = 2π/3`` of the flow's there is kept;
runs of kept samples are the candidate segments, scored by Eq. 3.10
``S = w1 l + w2 / (1 + d̄)`` with ``w1 = 1, w2 = 1e5`` and kept above ``S_min = 150``.

Where the thesis is silent we chose:

- SEcurves have no intrinsic direction (a principal curve could run up or down), so
  each is oriented to agree with the flow (the sign with the larger mean tangent dot
  product) before the θ_m test — otherwise the test would depend on an arbitrary choice.
- With the thesis' weights every segment within d_m scores at least 1e5/101 ≈ 990, so
  S_min never rejects one; the "conflicting segments" the thesis filters (both sides of
  a tree's contour near one stroke) are resolved by keeping, per SEcurve, only its
  best-scoring segment.
- The shared parametrisation maps the SEcurve segment by arc length onto the flow
  curve, centred at the closest point of its middle sample and as long as the segment
  (continued straight past the flow's ends when it is shorter): Eq. 3.11 equates
  derivatives, so equal lengths make it a shape match, not a stretch.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from authoring.flowcurves.hermite import resample_polyline, tangents

__all__ = ["Segment", "correspond", "D_M", "THETA_M", "W1", "W2", "S_MIN", "SPACING"]

from engine.arrays import F64 as F

D_M, THETA_M = 100.0, 2.0 * math.pi / 3.0
W1, W2, S_MIN = 1.0, 1e5, 150.0
#: Discretisation of SEcurves, pixels.
SPACING = 4.0


@dataclass
class Segment:
    """A corresponding pair: SEcurve samples ``c`` and flow-curve points ``gamma`` (same parameter)."""

    curve: int
    c: F
    gamma: F
    score: float


def discretise(points: ArrayLike, closed: bool = False, spacing: float = SPACING) -> F:
    """Resample a polyline (closed: back to its start) at about ``spacing`` pixels."""
    p = np.asarray(points, dtype=np.float64)
    if closed:
        p = np.vstack([p, p[:1]])
    length = float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum())
    q = resample_polyline(p, max(2, int(math.ceil(length / spacing)) + 1))
    return q[:-1] if closed else q


def _runs(keep: NDArray[np.bool_], closed: bool) -> list[NDArray[np.int64]]:
    idx = np.nonzero(keep)[0]
    if len(idx) == 0:
        return []
    breaks = np.nonzero(np.diff(idx) > 1)[0]
    runs = np.split(idx, breaks + 1)
    if closed and len(runs) > 1 and runs[0][0] == 0 and runs[-1][-1] == len(keep) - 1:
        runs[0] = np.r_[runs[-1], runs[0]]
        runs.pop()
    return runs


def _arc(p: F) -> F:
    return np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))]


def _on_flow(flow: F, arc: F, at: F) -> F:
    """Points at arc positions ``at``, continued straight along the end tangents past either end."""
    inside = np.clip(at, 0.0, arc[-1])
    p = np.c_[np.interp(inside, arc, flow[:, 0]), np.interp(inside, arc, flow[:, 1])]
    t = tangents(flow)
    p += np.minimum(at, 0.0)[:, None] * t[0] + np.maximum(at - arc[-1], 0.0)[:, None] * t[-1]
    return p


def correspond(
    securves: list[tuple[F, bool]], flow: ArrayLike, d_m: float = D_M, theta_m: float = THETA_M, s_min: float = S_MIN
) -> list[Segment]:
    """Segments of the SEcurves ``[(points, closed), …]`` that the flow curve (a dense polyline) takes."""
    g = np.asarray(flow, dtype=np.float64)
    g_tan, g_arc = tangents(g), _arc(g)
    g_lo, g_hi = g.min(axis=0), g.max(axis=0)
    out = []
    for ci, (points, closed) in enumerate(securves):
        p = np.asarray(points, dtype=np.float64)
        if np.linalg.norm(np.maximum(0.0, np.maximum(p.min(axis=0) - g_hi, g_lo - p.max(axis=0)))) >= d_m:
            continue  # its bounding box is beyond d_m of the flow's: no sample can be near (a network's far curves)
        c = discretise(p, closed)
        if len(c) < 2:
            continue
        c_tan = tangents(np.vstack([c[-1:], c, c[:1]]))[1:-1] if closed else tangents(c)
        d2 = ((c[:, None, :] - g[None]) ** 2).sum(axis=-1)
        j = np.argmin(d2, axis=1)
        dist = np.sqrt(d2[np.arange(len(c)), j])
        near = dist < d_m
        if not near.any():
            continue
        dots = np.sum(c_tan * g_tan[j], axis=1)
        if dots[near].mean() < 0:  # orient the SEcurve along the flow (see the module docstring)
            c, c_tan, j, dist, near, dots = c[::-1], -c_tan[::-1], j[::-1], dist[::-1], near[::-1], -dots[::-1]
        keep = near & (np.arccos(np.clip(dots, -1.0, 1.0)) < theta_m)
        best: Segment | None = None
        for run in _runs(keep, closed):
            if len(run) < 2:
                continue
            seg = c[run]
            length = float(np.linalg.norm(np.diff(seg, axis=0), axis=1).sum())
            score = W1 * length + W2 / (1.0 + float(dist[run].mean()))
            if score <= s_min or (best is not None and score <= best.score):
                continue
            s_arc = _arc(seg)
            mid = g_arc[j[run[len(run) // 2]]]
            start = mid - s_arc[len(run) // 2]
            best = Segment(ci, seg, _on_flow(g, g_arc, start + s_arc), score)
        if best is not None:
            out.append(best)
    return out
