"""A flow editing session: a scene, its SEcurves, the user's edits and the deformed result.

Edits are data — strokes, a centre-point, SEcurves drawn by hand — kept in order with
undo/redo; the deformed scene is always solved from the rest scene and the whole list
(see :mod:`authoring.flowcurves.deform`), so saving the edits is saving the result, and
a replayed session gives the same numbers. Only the last centre-point counts (the
thesis has one); dragging it edits it in place, re-bending its network from the last
answer.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from authoring.flowcurves.deform import SceneDeformer, Solve
from authoring.flowcurves.hermite import Hermite, fit_stroke, polyline_length
from authoring.flowcurves.network import D_MAX, FlowNetwork
from authoring.flowcurves.scene import FlowObject, FlowScene
from authoring.flowcurves.securves import SECurve, compute_securves

__all__ = ["FlowSession", "Edit", "dense"]

from engine.arrays import F64 as F


def dense(curve: Hermite, spacing: float = 2.0) -> F:
    """A flow curve as a polyline of about ``spacing`` pixels."""
    return curve.sample(max(16, int(curve.length() / spacing)))


@dataclass
class Edit:
    """One user edit: ``kind`` is ``stroke``, ``centre`` or ``securve``; ``points`` in pixels."""

    kind: str
    points: F
    d_max: float = D_MAX

    def as_json(self) -> dict[str, Any]:
        return {"kind": self.kind, "points": np.round(self.points, 3).tolist(), "d_max": self.d_max}


@dataclass
class FlowSession:
    """See the module docstring. ``securves`` may be given (tests, a reopened file) to skip their search."""

    scene: FlowScene
    securves: list[SECurve] | None = None
    progress: Callable[[int, int, str], None] | None = None
    edits: list[Edit] = field(default_factory=list)
    redo_stack: list[Edit] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.deformer = SceneDeformer(self.scene)
        self.auto_securves = (
            self.securves
            if self.securves is not None
            else compute_securves(self.scene, self.deformer.rasters, self.progress)
        )
        self.network: FlowNetwork | None = None
        self._network_key: tuple[float, ...] | None = None
        self.result = Solve({}, [], 0.0, 0.0)
        self.objects: list[FlowObject] = list(self.scene.objects)
        self.flows: list[Hermite] = []
        self._bent: tuple[Solve, list[F], list[F]] | None = None

    # -- edits --------------------------------------------------------------------------
    def all_securves(self) -> list[SECurve]:
        """Automatic SEcurves and the ones the user drew."""
        user = [SECurve.user(e.points, self._objects_under(e.points)) for e in self.edits if e.kind == "securve"]
        return list(self.auto_securves) + user

    def _objects_under(self, pts: F) -> list[int]:
        hit = [i for i, r in enumerate(self.deformer.rasters) if np.isfinite(r.depth_at(pts)).any()]
        if hit:
            return hit
        d = [
            float(np.sqrt(((pts[:, None] - e.grid.vertices[None]) ** 2).sum(-1)).min())
            for e in self.deformer.embeddings
        ]
        return [int(np.argmin(d))]

    def add(self, kind: str, points: ArrayLike, d_max: float = D_MAX) -> None:
        """Append an edit (clearing redo) and re-solve."""
        pts = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        if kind not in ("stroke", "centre", "securve"):
            raise ValueError(f"unknown edit {kind!r}")
        if kind != "centre" and (len(pts) < 2 or polyline_length(pts) < 4.0):
            raise ValueError("a stroke needs to be at least 4 px long")
        self.edits.append(Edit(kind, pts if kind != "centre" else pts.mean(axis=0, keepdims=True), d_max))
        self.redo_stack.clear()
        self.update()

    def move_centre(self, point: ArrayLike) -> None:
        """Drag the last centre-point (live: the network re-bends from its last curves)."""
        for e in reversed(self.edits):
            if e.kind == "centre":
                e.points = np.asarray(point, dtype=np.float64).reshape(1, 2)
                self.update(warm=True)
                return
        raise ValueError("there is no centre-point to move")

    def undo(self) -> bool:
        """Take back the last edit."""
        if not self.edits:
            return False
        self.redo_stack.append(self.edits.pop())
        self.update()
        return True

    def redo(self) -> bool:
        """Put back the last undone edit."""
        if not self.redo_stack:
            return False
        self.edits.append(self.redo_stack.pop())
        self.update()
        return True

    def bent_curves(self) -> tuple[list[F], list[F]]:
        """Every SEcurve and every taken segment as the bent objects carry them (§3.5.1: they are
        embedded in the same grids), so what is highlighted stays on the objects; kept per solve."""
        if self._bent is None or self._bent[0] is not self.result:
            moved = sorted(self.result.vertices)
            curves = [self.deformer.follow(c.points, c.objects, self.result) for c in self.all_securves()]
            segments = [self.deformer.follow(seg.c, moved, self.result) for seg in self.result.segments]
            self._bent = (self.result, curves, segments)
        return self._bent[1], self._bent[2]

    # -- solving ------------------------------------------------------------------------
    def _centre_curves(self, edit: Edit, warm: bool) -> list[Hermite]:
        spines = [s.points for s in self.spines()]
        key = (edit.d_max, float(len(spines)))
        if self.network is None or self._network_key != key or not warm:
            self.network = FlowNetwork.build(spines, edit.points[0], self.scene.size[0], edit.d_max)
            self._network_key = key
        else:
            self.network.move(edit.points[0], warm=True)
        return list(self.network.curves)

    def spines(self) -> list[SECurve]:
        """The open curves a centre-point's network grows from and acts on."""
        return [
            SECurve(s.spine, False, "spine", s.objects, s.spine) for s in self.all_securves() if s.spine is not None
        ]

    def update(self, warm: bool = False) -> None:
        """Solve the scene for the current edits."""
        strokes = [fit_stroke(e.points, self.scene.size[0]) for e in self.edits if e.kind == "stroke"]
        centres = [e for e in self.edits if e.kind == "centre"]
        network = self._centre_curves(centres[-1], warm) if centres else []
        if not centres:
            self.network = None
        self.flows = strokes + network
        self.result = self.deformer.solve(
            [([dense(f) for f in strokes], self.all_securves()), ([dense(f) for f in network], self.spines())]
        )
        self.objects = self.deformer.deformed_objects(self.result)
