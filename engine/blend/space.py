"""N-dimensional blend spaces: clips placed at points ``pᵢ ∈ [0,1]^N`` (thesis §6.2.3, Fig. 6.3).

For a point ``p`` the space returns weights over its clips and, from them, a blended
pose and root motion through the clips' shared phase (:mod:`engine.blend.sync`).

Why gradient-band interpolation (Johansen 2009; Unity's "freeform cartesian" blend
trees) rather than Delaunay-simplex barycentrics:

- it is defined on all of ``[0,1]^N`` and beyond, with no triangulation. The
  five clips of Fig. 6.3 sit on the corners and an edge of the unit square, which
  is a cospherical, degenerate Delaunay input (qhull must joggle it and the split
  of the square becomes arbitrary); in higher ``N`` grid-like layouts are the rule;
- it is continuous in ``p`` (a min and a clamp of affine functions), its weights are
  non-negative and sum to one, and a sample point gets exactly its own clip;
- it degrades gracefully: a sample far from ``p`` never gets weight through a long
  thin simplex, as barycentrics on sliver triangles do.

What it lacks is linear precision (a property that is linear over the samples is
not exactly reproduced between them), and that does not matter here: the lookup
table (:mod:`engine.blend.lookup`) measures what actually plays at each probe, so
any continuous weighting is mapped back exactly.

For each clip ``i`` and every other clip ``j``:
``hᵢⱼ(p) = 1 − (p − pᵢ)·(pⱼ − pᵢ) / |pⱼ − pᵢ|²``, ``hᵢ = clamp(minⱼ hᵢⱼ, 0, 1)``,
``wᵢ = hᵢ / Σₖ hₖ``. The sum is at least ½ (the nearest sample's ``hᵢⱼ ≥ ½`` for all j),
so the division is always safe.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TypedDict, Unpack

import numpy as np
from numpy.typing import ArrayLike

from engine import quat
from engine.arrays import I64
from engine.blend.pose_blend import blend_quaternions, blend_vectors
from engine.blend.sync import DEFAULT_SYNC_MARKERS, SyncGroup
from engine.clip import Clip
from engine.pose import Pose

__all__ = ["BlendSpace", "gradient_band_weights"]

from engine.arrays import F64 as F


def _blend_channels(pose: Pose, clips: list[Clip], pairs: list[tuple[I64, I64, F]], w: F) -> None:
    """Blend the clips' translation and scale channels into ``pose`` (only when some clip has one).

    A clip without a channel contributes its skeleton's offsets (or scale 1), so a stretching
    clip blended with a rigid one stretches by its weight.
    """
    offsets, scales = [], []
    for c, (i0, i1, a) in zip(clips, pairs, strict=True):
        tr = c.offsets()
        offsets.append(tr[i0] + np.asarray(a)[..., None, None] * (tr[i1] - tr[i0]))
        sc = np.ones((c.num_frames, c.skeleton.num_joints)) if c.scales is None else c.scales
        scales.append(sc[i0] + np.asarray(a)[..., None] * (sc[i1] - sc[i0]))
    wn = w / w.sum(axis=-1, keepdims=True)
    pose.offsets = np.sum(wn[..., None, None] * np.stack(offsets, axis=-3), axis=-3)
    pose.scales = np.sum(wn[..., None] * np.stack(scales, axis=-2), axis=-2)


def gradient_band_weights(points: ArrayLike, p: ArrayLike) -> F:
    """Gradient-band weights ``[..., K]`` of query points ``p [..., N]`` over samples ``points [K, N]``."""
    pts = np.asarray(points, dtype=np.float64)
    q = np.asarray(p, dtype=np.float64)
    k = len(pts)
    if k == 1:
        return np.ones(q.shape[:-1] + (1,))
    d = pts[None, :, :] - pts[:, None, :]  # [K(i), K(j), N]: p_j - p_i
    inv_len2 = 1.0 / np.where(np.eye(k, dtype=bool), 1.0, np.sum(d * d, axis=-1))
    rel = q[..., None, :] - pts  # [..., K, N]: p - p_i
    h = 1.0 - np.einsum("...in,ijn->...ij", rel, d) * inv_len2
    h = np.where(np.eye(k, dtype=bool), np.inf, h)
    hi = np.clip(h.min(axis=-1), 0.0, 1.0)
    return hi / hi.sum(axis=-1, keepdims=True)


class _SpaceOptions(TypedDict, total=False):
    """The optional fields of :class:`BlendSpace`, as keywords of :meth:`BlendSpace.from_named`."""

    markers: tuple[str, ...]
    method: str


@dataclass(frozen=True)
class BlendSpace:
    """Cyclic clips placed in an N-D parameter space, played in phase.

    Args:
        clips: looping clips, all on the same skeleton.
        points: ``[K, N]`` positions in ``[0, 1]^N``, one per clip, all distinct.
        axes: names of the ``N`` parameters (e.g. ``("velocity", "height")``).
        markers: sync markers shared by the clips.
        method: quaternion blend (``"nlerp"`` or ``"mean"``), see :func:`blend_quaternions`.
    """

    clips: tuple[Clip, ...]
    points: F
    axes: tuple[str, ...]
    markers: tuple[str, ...] = DEFAULT_SYNC_MARKERS
    method: str = "nlerp"
    sync: SyncGroup = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        pts = np.array(self.points, dtype=np.float64)
        if pts.ndim != 2 or len(pts) != len(self.clips) or pts.shape[1] != len(self.axes):
            raise ValueError(
                f"points must be [K={len(self.clips)}, N={len(self.axes)}], one per clip and axis; got {pts.shape}"
            )
        if not np.isfinite(pts).all() or pts.min() < 0.0 or pts.max() > 1.0:
            raise ValueError("blend-space points must lie in [0, 1]^N")
        gaps = np.linalg.norm(pts[:, None] - pts[None], axis=-1) + np.eye(len(pts))
        if np.any(gaps < 1e-9):
            raise ValueError("two clips share a point of the blend space")
        if self.method not in ("nlerp", "mean"):
            raise ValueError(f"unknown blend method {self.method!r}")
        pts.setflags(write=False)
        object.__setattr__(self, "points", pts)
        object.__setattr__(self, "sync", SyncGroup(tuple(self.clips), tuple(self.markers)))

    @classmethod
    def from_named(
        cls,
        clips: Mapping[str, Clip],
        placement: Mapping[str, Sequence[float]],
        axes: Sequence[str],
        **kw: Unpack[_SpaceOptions],
    ) -> BlendSpace:
        """Build from ``{clip name: point}``; a name without a clip is a clear error."""
        missing = [n for n in placement if n not in clips]
        if missing:
            raise KeyError(f"blend space needs clips {missing}; available: {sorted(clips)}")
        names = list(placement)
        points = np.array([placement[n] for n in names], dtype=np.float64)
        return cls(tuple(clips[n] for n in names), points, tuple(axes), **kw)

    @property
    def names(self) -> tuple[str, ...]:
        """Clip names, in sample order."""
        return tuple(c.name for c in self.clips)

    @property
    def dims(self) -> int:
        """Number of parameters ``N``."""
        return int(self.points.shape[1])

    def weights(self, p: ArrayLike) -> F:
        """Clip weights ``[..., K]`` at points ``p [..., N]``: continuous, non-negative, summing to one."""
        q = np.asarray(p, dtype=np.float64)
        if q.shape[-1:] != (self.dims,):
            raise ValueError(f"blend point must end in {self.dims} values ({', '.join(self.axes)}), got {q.shape}")
        return gradient_band_weights(self.points, q)

    def sample(self, weights: ArrayLike, phase: ArrayLike) -> Pose:
        """The blended in-place pose (batch ``[...]``) at group ``phase [...]`` with ``weights [..., K]``."""
        w = np.asarray(weights, dtype=np.float64)
        # Only clips with weight somewhere in the batch are sampled (gradient bands are local:
        # two or three of the five puppet clips at a time).
        active = np.flatnonzero(np.any(w.reshape(-1, len(self.clips)) > 0.0, axis=0))
        times = self.sync.clip_times(phase, active)
        clips = [self.clips[k] for k in active]
        pairs = [c.frame_pair(times[..., i]) for i, c in enumerate(clips)]
        root = np.stack(
            [
                c.root[i0] + a[..., None] * (c.root[i1] - c.root[i0])
                for c, (i0, i1, a) in zip(clips, pairs, strict=True)
            ],
            axis=-2,
        )  # [..., K', 3]
        # one slerp for every active clip (Clip.sample's, element for element, without K' dispatches)
        r0 = np.stack([c.rotations[i0] for c, (i0, _, _) in zip(clips, pairs, strict=True)])
        r1 = np.stack([c.rotations[i1] for c, (_, i1, _) in zip(clips, pairs, strict=True)])
        frac = np.stack([np.asarray(a) for _, _, a in pairs])[..., None]
        rot = np.stack(list(quat.slerp(r0, r1, frac)), axis=-2)  # [..., J, K', 4]
        wa = w[..., active]
        pose = Pose(blend_vectors(wa, root), blend_quaternions(wa[..., None, :], rot, self.method))
        if any(c.translations is not None or c.scales is not None for c in clips):
            _blend_channels(pose, clips, pairs, wa)
        return pose

    def sample_root(self, weights: ArrayLike, phase: ArrayLike) -> F:
        """Only the blended root position ``[..., 3]`` (what measuring heights needs; no joint slerps)."""
        w = np.asarray(weights, dtype=np.float64)
        times = self.sync.clip_times(phase)
        roots = []
        for k, clip in enumerate(self.clips):
            f = np.mod(times[..., k] * clip.fps, clip.num_frames)
            i0 = np.floor(f).astype(np.int64) % clip.num_frames
            i1 = (i0 + 1) % clip.num_frames
            a = (f - np.floor(f))[..., None]
            roots.append(clip.root[i0] + a * (clip.root[i1] - clip.root[i0]))
        return blend_vectors(w, np.stack(roots, axis=-2))

    def cycle_duration(self, weights: ArrayLike) -> F:
        """Seconds of one blended cycle."""
        return self.sync.cycle_duration(weights)

    def advance(self, phase: ArrayLike, weights: ArrayLike, dt: float, rate: ArrayLike = 1.0) -> tuple[F, F, F]:
        """Play ``dt`` seconds: the new phase, root travel ``[..., 3]`` (clip frame) and heading change ``[...]``."""
        new_phase = self.sync.advance(phase, weights, dt, rate)
        travel, turn = self.sync.root_delta(phase, new_phase, weights)
        return new_phase, travel, turn

    def average_velocity(self, weights: ArrayLike) -> F:
        """Mean root velocity ``[..., 3]`` of the blend over a whole cycle (analytic, for checks)."""
        w = np.asarray(weights, dtype=np.float64)
        travel = self.sync.cycle_travels()
        return (w @ travel) / self.cycle_duration(w)[..., None]
