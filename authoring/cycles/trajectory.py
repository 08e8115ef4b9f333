"""The performed trajectory: times, a ``[T, N]`` value array, and the items that own its columns.

The cycle extractor works on one N-dimensional curve (paper §4), but the values
are not all alike: a column may be a coordinate of a position, one of the four
components of a quaternion, a scale or a plain scalar. The extractor needs to know
which, because quaternions are averaged and stitched on the sphere, not as raw
numbers, and because a root position may legitimately *travel* (a walk moves
forward each cycle) while everything else must close on itself.

An :class:`Item` names a slice of columns and its kind; a :class:`Trajectory`
validates everything once (finite values, increasing times, unit quaternions on one
continuous hemisphere) so the algorithm never sees bad input.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from engine import quat
from engine.errors import FormatError

__all__ = ["KINDS", "Item", "Trajectory", "TrajectoryError", "continuous_quaternions"]

KINDS = ("position", "rotation", "scale", "scalar")
_WIDTH = {"position": 3, "rotation": 4, "scale": 3}


# No performance is measured in units this large (mocap in millimetres stays under 1e5).
MAX_MAGNITUDE = 1e7


class TrajectoryError(FormatError):
    """A performed trajectory that cannot be analysed (bad shape, NaN, times not increasing…)."""


@dataclass(frozen=True)
class Item:
    """A named group of columns that is one thing to animate.

    Attributes:
        name: e.g. ``"l_foot.rotation"`` or ``"stick.position"``.
        kind: one of :data:`KINDS`; ``rotation`` columns are a unit quaternion ``(w,x,y,z)``.
        start: first column in the value array.
        stop: one past the last column.
        travel: a position that may move on every cycle (a root walking forward); its net
            per-cycle travel is kept where it is statistically significant instead of being
            stitched away.
    """

    name: str
    kind: str
    start: int
    stop: int
    travel: bool = False

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise TrajectoryError(f"item {self.name!r}: kind {self.kind!r} is not one of {KINDS}")
        if not 0 <= self.start < self.stop:
            raise TrajectoryError(f"item {self.name!r}: empty or negative column range {self.start}:{self.stop}")
        width = _WIDTH.get(self.kind)
        if self.kind == "rotation" and self.stop - self.start != 4:
            raise TrajectoryError(
                f"item {self.name!r}: a rotation is 4 quaternion columns, got {self.stop - self.start}"
            )
        if width is not None and self.kind != "rotation" and self.stop - self.start > width:
            raise TrajectoryError(f"item {self.name!r}: a {self.kind} has at most {width} columns")

    @property
    def columns(self) -> slice:
        """The item's columns as a slice."""
        return slice(self.start, self.stop)


@dataclass(frozen=True)
class Trajectory:
    """A performance ``t_i -> θ_i`` (paper §4), validated.

    Attributes:
        times: ``[T]`` strictly increasing seconds (sampling may be uneven).
        values: ``[T, N]`` values; quaternion items are made unit and hemisphere-continuous.
        items: the items covering the columns; by default one ``scalar`` item per column.
    """

    times: NDArray[np.float64]
    values: NDArray[np.float64]
    items: tuple[Item, ...] = field(default=())

    def __post_init__(self) -> None:
        t = np.asarray(self.times, dtype=np.float64).reshape(-1)
        v = np.asarray(self.values, dtype=np.float64)
        if v.ndim == 1:
            v = v[:, None]
        if v.ndim != 2 or len(v) != len(t):
            raise TrajectoryError(f"values must be [T,N] with T = {len(t)} times, got shape {v.shape}")
        if v.shape[1] == 0:
            raise TrajectoryError("the trajectory has no dimensions")
        if not (np.isfinite(t).all() and np.isfinite(v).all()):
            bad = np.argwhere(~np.isfinite(v))
            where = f" (first at frame {bad[0][0]}, column {bad[0][1]})" if len(bad) else ""
            raise TrajectoryError(f"the trajectory contains NaN or infinite values{where}")
        big = max(float(np.abs(t).max(initial=0.0)), float(np.abs(v).max(initial=0.0)))
        if big > MAX_MAGNITUDE:  # finite, but the fit's sums of squares would overflow to inf
            raise TrajectoryError(
                f"the trajectory holds a value of {big:.3g}; values and times stay within ±{MAX_MAGNITUDE:g}"
            )
        if len(t) > 1 and not np.all(np.diff(t) > 0):
            i = int(np.argmin(np.diff(t)))
            raise TrajectoryError(f"times must increase strictly (frame {i + 1}: {t[i + 1]} after {t[i]})")
        items = tuple(self.items) or tuple(Item(f"c{c}", "scalar", c, c + 1) for c in range(v.shape[1]))
        covered = np.zeros(v.shape[1], dtype=np.int64)
        for it in items:
            if it.stop > v.shape[1]:
                raise TrajectoryError(f"item {it.name!r} reaches column {it.stop - 1} of {v.shape[1]}")
            covered[it.columns] += 1
        if np.any(covered > 1):
            raise TrajectoryError(f"column {int(np.argmax(covered > 1))} belongs to more than one item")
        v = v.copy()
        for it in items:
            if it.kind == "rotation":
                v[:, it.columns] = continuous_quaternions(v[:, it.columns])
        t = t.copy()
        t.setflags(write=False)
        v.setflags(write=False)
        object.__setattr__(self, "times", t)
        object.__setattr__(self, "values", v)
        object.__setattr__(self, "items", items)

    @classmethod
    def uniform(cls, values: ArrayLike, fps: float, items: tuple[Item, ...] | list[Item] = ()) -> Trajectory:
        """A trajectory sampled at a constant ``fps``."""
        if fps <= 0:
            raise TrajectoryError(f"fps must be positive, got {fps}")
        v = np.asarray(values, dtype=np.float64)
        return cls(np.arange(len(v)) / float(fps), v, tuple(items))

    @property
    def num_samples(self) -> int:
        """Number of samples ``T``."""
        return len(self.times)

    @property
    def dims(self) -> int:
        """Number of dimensions ``N``."""
        return int(self.values.shape[1])

    @property
    def dt(self) -> float:
        """Median sampling interval in seconds."""
        return float(np.median(np.diff(self.times))) if len(self.times) > 1 else 1.0

    def rotation_items(self) -> list[Item]:
        """The quaternion items."""
        return [it for it in self.items if it.kind == "rotation"]

    def weights(self) -> NDArray[np.float64]:
        """Per-column weights that put every kind of value on a comparable footing.

        Positions in centimetres would otherwise drown rotations in quaternion units:
        each *kind* is divided by the pooled RMS speed of its columns, so kinds weigh
        alike while columns within a kind keep their relative importance (a still joint
        stays unimportant).
        """
        w = np.ones(self.dims)
        if self.num_samples < 3:
            return w
        speed = np.diff(self.values, axis=0) / np.diff(self.times)[:, None]
        for kind in KINDS:
            cols = np.concatenate(
                [np.arange(it.start, it.stop) for it in self.items if it.kind == kind] or [np.zeros(0, int)]
            )
            if len(cols) == 0:
                continue
            rms = float(np.sqrt(np.mean(speed[:, cols] ** 2)))
            share = sum(1 for it in self.items if it.kind == kind) / len(self.items)
            if rms > 1e-12:
                w[cols] = np.sqrt(share) / rms
        return w


def continuous_quaternions(q: ArrayLike) -> NDArray[np.float64]:
    """Unit quaternions ``[T,4]`` with each sign chosen to continue the previous one.

    ``q`` and ``-q`` are one rotation; without this a curve of quaternion components
    jumps across the sphere and neither derivatives nor averages make sense.
    """
    q = quat.normalize(np.asarray(q, dtype=np.float64))
    if len(q) < 2:
        return q
    # Flip where the dot product with the previous sample is negative, cumulatively.
    d = np.einsum("ij,ij->i", q[1:], q[:-1])
    flips = np.concatenate([[0], np.cumsum(d < 0)]) % 2
    return np.where(flips[:, None] == 1, -q, q)
