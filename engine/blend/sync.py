"""Phase synchronisation of cyclic clips: one normalised phase drives every clip of a blend.

Blending a walk with a run frame-by-frame in their own times puts the left foot of
one on the ground while the other lifts it: the blend shuffles. A *sync group*
(Unity's blend-tree time normalisation, Unreal's sync markers) instead drives all
clips from one phase ``φ ∈ [0, 1)``:

- Each clip maps ``φ`` to its own normalised time through its sync markers: with
  markers ``left_down = 0.0`` and ``right_down = 0.5`` the group phase ``0`` is every
  clip's left contact and ``0.5`` every clip's right contact; between markers the
  map is linear. A clip whose right contact is at 0.47 is thus warped so its
  contacts still coincide with the others'.
- The blended cycle lasts ``Σ wᵢ·Tᵢ`` (the weighted mean of the clip durations), so
  ``φ`` advances by ``dt / Σ wᵢTᵢ`` per step and the blend's cadence moves smoothly
  from the walk's to the run's.
- Root motion over a step is the weighted sum of each clip's travel over the same
  phase interval, which is what makes the blended feet stay planted.

Phases are unwrapped floats here (``φ = 2.3`` is 0.3 into the third cycle), so root
motion accumulates across loops without special cases.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from engine.clip import Clip

__all__ = ["SyncGroup", "DEFAULT_SYNC_MARKERS"]

from engine.arrays import F64 as F

DEFAULT_SYNC_MARKERS: tuple[str, ...] = ("left_down", "right_down")


def _marker_warp(clip: Clip, names: Sequence[str]) -> tuple[F, F]:
    """Knots ``(phase, clip normalised time)`` of one period of the clip's phase warp.

    Markers missing from a clip fall back to evenly spaced times (an idle that has no
    contacts still loops in step). Knots are made monotonic from the first marker on.
    """
    n = len(names)
    present = [clip.markers.get(name) for name in names]
    if any(m is None for m in present):
        start = float(present[0]) if present[0] is not None else 0.0
        times = start + np.arange(n) / n
    else:
        times = np.array(present, dtype=np.float64)
        times = times[0] + np.mod(times - times[0], 1.0)
        if np.any(np.diff(times) <= 0.0):
            raise ValueError(f"clip {clip.name!r}: sync markers {list(names)} must be distinct and in cyclic order")
    phases = np.arange(n + 1) / n
    return phases, np.append(times, times[0] + 1.0)


def _root_table(clip: Clip) -> tuple[F, F]:
    """Per-frame ``(x, y, z, heading)`` of a loop's root motion, closing frame appended; and one cycle's travel."""
    n = clip.num_frames
    rm = clip.root_motion
    if rm is None:
        return np.zeros((n + 1, 4)), np.zeros(4)
    travel, turn = clip.cycle_travel()
    table = np.zeros((n + 1, 4))
    table[:n, :3] = rm.translation
    table[:n, 3] = rm.heading
    cycle = np.append(travel, turn)
    table[n] = table[0] + cycle
    return table, cycle


@dataclass(frozen=True)
class SyncGroup:
    """Cyclic clips driven by one shared phase.

    Args:
        clips: the looping clips (all with the same skeleton).
        markers: the sync marker names, in the order they occur in a cycle.
    """

    clips: tuple[Clip, ...]
    markers: tuple[str, ...] = DEFAULT_SYNC_MARKERS
    _knots: tuple[tuple[F, F], ...] = field(init=False, repr=False, compare=False)
    durations: F = field(init=False, repr=False, compare=False)
    _root_tables: tuple[tuple[F, F], ...] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if not self.clips:
            raise ValueError("a sync group needs at least one clip")
        sk = self.clips[0].skeleton
        for c in self.clips:
            if not c.loop:
                raise ValueError(f"clip {c.name!r} is not a loop: only cycles can be phase-synchronised")
            if c.skeleton.num_joints != sk.num_joints or c.skeleton.names != sk.names:
                raise ValueError(f"clip {c.name!r} animates another skeleton than {self.clips[0].name!r}")
        if not self.markers:
            raise ValueError("a sync group needs at least one marker name")
        object.__setattr__(self, "_knots", tuple(_marker_warp(c, self.markers) for c in self.clips))
        durations = np.array([c.duration for c in self.clips], dtype=np.float64)
        durations.setflags(write=False)
        object.__setattr__(self, "durations", durations)
        object.__setattr__(self, "_root_tables", tuple(_root_table(c) for c in self.clips))

    def cycle_travels(self) -> F:
        """Root travel ``[K, 3]`` of each clip over one whole cycle."""
        return np.stack([cycle[:3] for _, cycle in self._root_tables])

    def cycle_duration(self, weights: ArrayLike) -> F:
        """Seconds of one blended cycle, ``Σ wᵢTᵢ`` for weights ``[..., K]`` summing to one."""
        return np.asarray(weights, dtype=np.float64) @ self.durations

    def _indices(self, active: ArrayLike | None) -> list[int]:
        """Clip indices to evaluate: ``active`` (those with weight), or every clip."""
        return list(range(len(self.clips))) if active is None else [int(k) for k in np.asarray(active).reshape(-1)]

    def clip_times(self, phase: ArrayLike, active: ArrayLike | None = None) -> F:
        """Each clip's unwrapped local time in seconds at group phase ``phase [...]``: ``[..., K]``,
        or ``[..., K']`` for the clip indices ``active`` only (the ones with weight)."""
        phase = np.asarray(phase, dtype=np.float64)
        cycles = np.floor(phase)
        frac = phase - cycles
        ks = self._indices(active)
        out = np.empty(phase.shape + (len(ks),))
        for i, k in enumerate(ks):
            xp, fp = self._knots[k]
            # Normalised clip time, shifted so the first marker lands on phase 0.
            local = np.interp(frac, xp, fp)
            out[..., i] = (cycles + local) * self.durations[k]
        return out

    def advance(self, phase: ArrayLike, weights: ArrayLike, dt: float, rate: ArrayLike = 1.0) -> F:
        """The phase after ``dt`` seconds of playback at ``rate`` (1 = authored speed)."""
        return np.asarray(phase, dtype=np.float64) + dt * np.asarray(rate, dtype=np.float64) / self.cycle_duration(
            weights
        )

    def root_motion(self, phase: ArrayLike, active: ArrayLike | None = None) -> tuple[F, F]:
        """Accumulated root travel ``[..., K, 3]`` and heading ``[..., K]`` of every clip at ``phase``
        (``K'`` of them with ``active``).

        Vectorised equivalent of :meth:`Clip.sample_root_motion` over a batch of times.
        """
        ks = self._indices(active)
        times = self.clip_times(phase, active)
        trans = np.empty(times.shape + (3,))
        head = np.empty(times.shape)
        for i, k in enumerate(ks):
            table, cycle = self._root_tables[k]
            n = len(table) - 1
            f = times[..., i] * self.clips[k].fps
            cycles = np.floor(f / n)
            local = f - cycles * n
            i0 = np.minimum(np.floor(local).astype(np.int64), n - 1)
            a = (local - i0)[..., None]
            row = table[i0] + a * (table[i0 + 1] - table[i0]) + cycles[..., None] * cycle
            trans[..., i, :] = row[..., :3]
            head[..., i] = row[..., 3]
        return trans, head

    def root_delta(self, phase0: ArrayLike, phase1: ArrayLike, weights: ArrayLike) -> tuple[F, F]:
        """Blended root travel ``[..., 3]`` (clip frame) and heading change ``[...]`` from ``phase0`` to ``phase1``."""
        p0, p1 = np.broadcast_arrays(np.asarray(phase0, dtype=np.float64), np.asarray(phase1, dtype=np.float64))
        w = np.asarray(weights, dtype=np.float64)
        active = np.flatnonzero(
            np.any(w.reshape(-1, len(self.clips)) > 0.0, axis=0)
        )  # clips without weight add nothing
        trans, head = self.root_motion(np.stack([p0, p1]), active)  # one pass over the clips for both ends
        t0, t1, h0, h1 = trans[0], trans[1], head[0], head[1]
        w = w[..., active]
        return np.sum(w[..., None] * (t1 - t0), axis=-2), np.sum(w * (h1 - h0), axis=-1)
