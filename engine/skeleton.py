"""Skeletons: joint names, parents and rest offsets, as immutable numpy-backed assets.

Joints are stored in topological order (a parent always comes before its children),
so forward kinematics can walk them level by level. Coordinates are metres, Y up,
and a character faces +Z in its rest pose (the glTF convention).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["Skeleton"]


@dataclass(frozen=True)
class Skeleton:
    """A joint hierarchy.

    Attributes:
        names: joint names, unique.
        parents: parent index per joint, ``-1`` for the root (joint 0).
        offsets: ``[J,3]`` translation of each joint from its parent in the parent's frame
            (the root's offset is its rest position relative to the root translation).
        tips: ``[J,3]`` end point of each joint's bone in its own frame, for leaves that have
            no child to point at (BVH "End Site"); zero where a child defines the bone.
        radii: ``[J]`` bone thickness used by the renderer and the ragdoll.
    """

    names: tuple[str, ...]
    parents: NDArray[np.int64]
    offsets: NDArray[np.float64]
    # None means "derive": __post_init__ always replaces it with an array, so readers see one.
    tips: NDArray[np.float64] = field(default=None)  # type: ignore[arg-type]  # filled in __post_init__
    radii: NDArray[np.float64] = field(default=None)  # type: ignore[arg-type]  # filled in __post_init__

    def __post_init__(self) -> None:
        parents = np.asarray(self.parents, dtype=np.int64)
        offsets = np.asarray(self.offsets, dtype=np.float64).reshape(-1, 3)
        n = len(self.names)
        if parents.shape != (n,) or offsets.shape != (n, 3):
            raise ValueError(f"skeleton of {n} joints needs {n} parents and [{n},3] offsets")
        if len(set(self.names)) != n:
            raise ValueError("joint names must be unique")
        if n == 0 or parents[0] != -1:
            raise ValueError("joint 0 must be the root (parent -1)")
        for j in range(1, n):
            if not 0 <= parents[j] < j:
                raise ValueError(f"joint {self.names[j]!r}: parent {parents[j]} must come before it")
        tips = np.zeros((n, 3)) if self.tips is None else np.asarray(self.tips, dtype=np.float64).reshape(n, 3)
        radii = np.full(n, 0.05) if self.radii is None else np.asarray(self.radii, dtype=np.float64).reshape(n)
        for name, value in (("parents", parents), ("offsets", offsets), ("tips", tips), ("radii", radii)):
            value.setflags(write=False)
            object.__setattr__(self, name, value)
        object.__setattr__(self, "names", tuple(self.names))

    @property
    def num_joints(self) -> int:
        """Number of joints ``J``."""
        return len(self.names)

    def index(self, name: str) -> int:
        """Index of a joint by name, with a clear error naming the known joints."""
        try:
            return self.names.index(name)
        except ValueError:
            raise KeyError(f"no joint {name!r}; joints are {', '.join(self.names)}") from None

    def children(self, j: int) -> list[int]:
        """Direct children of joint ``j`` in index order."""
        return [int(c) for c in np.nonzero(self.parents == j)[0]]

    def chain(self, start: str | int, end: str | int) -> list[int]:
        """Joint indices from ``start`` down to its descendant ``end``, both included."""
        s = start if isinstance(start, int) else self.index(start)
        e = end if isinstance(end, int) else self.index(end)
        path = [e]
        while path[-1] != s:
            p = int(self.parents[path[-1]])
            if p < 0:
                raise ValueError(f"{self.names[e]!r} does not descend from {self.names[s]!r}")
            path.append(p)
        return path[::-1]

    def depths(self) -> NDArray[np.int64]:
        """Depth of each joint (root 0), used to batch FK by level."""
        d = np.zeros(self.num_joints, dtype=np.int64)
        for j in range(1, self.num_joints):
            d[j] = d[self.parents[j]] + 1
        return d

    def bone_lengths(self) -> NDArray[np.float64]:
        """Length of each joint's bone: to its first child, or to its tip for a leaf."""
        lengths = np.linalg.norm(self.tips, axis=1)
        for j in range(self.num_joints - 1, 0, -1):
            lengths[self.parents[j]] = max(lengths[self.parents[j]], 0.0)
        for j in range(self.num_joints):
            kids = self.children(j)
            if kids:
                lengths[j] = float(np.linalg.norm(self.offsets[kids[0]]))
        return lengths

    def with_offsets(self, offsets: ArrayLike, tips: ArrayLike | None = None) -> Skeleton:
        """The same hierarchy with other bone lengths (snowmen, retargeting)."""
        return Skeleton(
            self.names,
            self.parents,
            np.asarray(offsets),
            self.tips if tips is None else np.asarray(tips, dtype=np.float64),
            self.radii,
        )
