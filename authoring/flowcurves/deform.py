"""Deforming a scene so its SEcurves follow flow curves (§3.5, Eq. 3.9–3.12).

:class:`SceneDeformer` holds what does not change while the user sketches — the
objects' footprints, grid embeddings and contacts — and turns a list of flow curves
into deformed objects:

1. correspondence (§3.5.2) picks the SEcurve segments each flow curve takes;
2. each segment's samples are attached to the object seen at that pixel (the nearest
   one of its objects when none covers it) and become shape constraints; the flow
   segment is first moved to pass through the SEcurve where it is held — the point
   nearest a ground contact of the objects it drags along — or, for objects that touch
   nothing fixed, left where it is so they translate onto the stroke (§3.5.3);
3. the objects linked to those by contacts are solved together by ARAP
   (:class:`~authoring.flowcurves.arap.ArapSystem`), the contacts kept exactly; the
   factorisation is reused while the constraint rows stay the same (a dragged
   centre-point usually moves targets, not rows);
4. no planted object may topple: when following the strokes all the way would turn a
   planted object's base past :data:`~authoring.flowcurves.tilt.MAX_BASE_TILT_DEG`, the
   targets are followed the largest part of the way that keeps every base within it
   (``Solve.reach`` < 1, found by bisection over the prefactored system);
5. Eq. 3.9 lifts the deformed grids back to 3D primitives and mesh vertices.

Every solve starts from the rest pose, so the same edits give the same scene whatever
was tried in between (undo, redo, a drag that came back).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from authoring.flowcurves.arap import W_SHAPE, ArapSystem
from authoring.flowcurves.contacts import Contact, find_contacts
from authoring.flowcurves.correspondence import Segment, correspond
from authoring.flowcurves.grid import GRID_SPACING, Embedding, lift
from authoring.flowcurves.scene import FlowObject, FlowScene, Raster, rasterize
from authoring.flowcurves.securves import SECurve
from authoring.flowcurves.tilt import MAX_BASE_TILT_DEG, base_tilt_deg

__all__ = ["SceneDeformer", "Solve", "ITERATIONS", "REACH_STEPS"]

from engine.arrays import F64 as F

ITERATIONS = 8
#: Bisection steps for the part of the way a stroke is followed when a base would tilt too far
#: (2⁻⁸ of the way: under a pixel for strokes that move objects less than 256 px).
REACH_STEPS = 8
_SCREEN_UP = np.array([0.0, -1.0])
_WORLD_UP = np.array([0.0, 1.0, 0.0])


@dataclass
class Solve:
    """One solve's result: deformed grid vertices per object (absent: unchanged) and what it took."""

    vertices: dict[int, F]
    segments: list[Segment]
    factor_ms: float
    solve_ms: float
    system: ArapSystem | None = None
    offsets: dict[int, int] | None = None
    reach: float = 1.0
    """The part of the way the targets were followed (1: all of it; less: a base reached the tilt limit)."""
    tilt_deg: float = 0.0
    """The largest base rotation of a planted object, on screen, in degrees."""


class SceneDeformer:
    """A scene's grids and contacts, ready to follow flow curves."""

    def __init__(
        self, scene: FlowScene, rasters: list[Raster] | None = None, spacing: float = GRID_SPACING, stride: int = 2
    ) -> None:
        self.scene = scene
        self.rasters = rasters or [rasterize(o, scene.camera, scene.size, stride) for o in scene.objects]
        self.embeddings = [
            Embedding.of(o, r, scene.camera, scene.size, spacing) for o, r in zip(scene.objects, self.rasters)
        ]
        self.contacts: list[Contact] = find_contacts(scene)
        parent = list(range(len(scene.objects)))

        def root(a: int) -> int:
            while parent[a] != a:
                a = parent[a]
            return a

        for c in self.contacts:
            if c.b is not None:
                parent[root(c.b)] = root(c.a)
        self.component = [root(i) for i in range(len(scene.objects))]
        self.planted = sorted({c.a for c in self.contacts if c.b is None})
        self.shape_weight = W_SHAPE  # Eq. 3.12's shape constraints' weight (see arap's docstring for why soft)
        self._cache: tuple[object, ArapSystem] | None = None
        self._hard: tuple[tuple[int, ...], sp.csr_matrix] | None = None

    # -- constraints --------------------------------------------------------------------
    def owners(self, xy: F, objects: list[int]) -> NDArray[np.int64]:
        """The object seen at each pixel among ``objects`` (nearest grid when none covers it)."""
        depth = np.stack([self.rasters[o].depth_at(xy) for o in objects], axis=1)
        pick = np.argmin(depth, axis=1)
        bare = ~np.isfinite(depth).any(axis=1)
        if bare.any():  # the nearest grid only for the pixels no object covers
            near = np.stack(
                [((xy[bare, None, :] - self.embeddings[o].grid.vertices[None]) ** 2).sum(-1).min(1) for o in objects],
                axis=1,
            )
            pick[bare] = np.argmin(near, axis=1)
        return np.asarray(objects, dtype=np.int64)[pick]

    def fixed_points(self, objects: set[int]) -> F:
        """Ground-contact points of every object linked to ``objects``."""
        comps = {self.component[o] for o in objects}
        pts = [c.points for c in self.contacts if c.b is None and self.component[c.a] in comps]
        return np.vstack(pts) if pts else np.zeros((0, 2))

    def segments(self, flows: list[F], securves: list[SECurve]) -> list[tuple[Segment, NDArray[np.int64], F]]:
        """Per taken segment: its owners per sample and the targets (the anchored flow segment)."""
        curves = [(s.points, s.closed) for s in securves]
        out: list[tuple[Segment, NDArray[np.int64], F]] = []
        for flow in flows:
            for seg in correspond(curves, flow):
                owners = self.owners(seg.c, securves[seg.curve].objects)
                fixed = self.fixed_points(set(owners.tolist()))
                targets = seg.gamma
                if len(fixed):
                    d = np.sqrt(((seg.c[:, None, :] - fixed[None]) ** 2).sum(-1)).min(axis=1)
                    k = int(np.argmin(d))
                    targets = seg.gamma + (seg.c[k] - seg.gamma[k])
                out.append((seg, owners, targets))
        return out

    # -- solving ------------------------------------------------------------------------
    def _system(self, active: list[int], soft: list[tuple[int, F]]) -> tuple[ArapSystem, dict[int, int], float]:
        key = (tuple(active), tuple((o, xy.tobytes()) for o, xy in soft), self.shape_weight)
        offsets, n = {}, 0
        for o in active:
            offsets[o] = n
            n += len(self.embeddings[o].grid.vertices)
        if self._cache is not None and self._cache[0] == key:
            return self._cache[1], offsets, 0.0
        t0 = time.perf_counter()
        if self._hard is None or self._hard[0] != key[0]:  # contact rows change only with the active objects
            blocks = [
                [(c.a, c.points, 1.0)] + ([(c.b, c.points, -1.0)] if c.b is not None else [])
                for c in self.contacts
                if c.a in offsets
            ]
            self._hard = (key[0], self._rows(blocks, offsets, n))
        rest = np.vstack([self.embeddings[o].grid.vertices for o in active])
        tris = np.vstack([self.embeddings[o].grid.triangles + offsets[o] for o in active])
        system = ArapSystem(
            rest, tris, self._hard[1], self._rows([[(o, xy, 1.0)] for o, xy in soft], offsets, n), self.shape_weight
        )
        self._cache = (key, system)
        return system, offsets, (time.perf_counter() - t0) * 1e3

    def _rows(self, blocks: list[list[tuple[int, F, float]]], offsets: dict[int, int], n: int) -> sp.csr_matrix:
        """One sparse matrix of point rows: each block is points on objects (with a sign), summed
        row by row — a contact is its points on one object minus the same points on the other."""
        rows, cols, vals, start = [], [], [], 0
        for block in blocks:
            m = len(block[0][1])
            for o, xy, sign in block:
                grid = self.embeddings[o].grid
                t, bary = grid.locate(np.asarray(xy, dtype=np.float64).reshape(-1, 2))
                rows.append(np.repeat(np.arange(start, start + m), 3))
                cols.append(grid.triangles[t].ravel() + offsets[o])
                vals.append(sign * bary.ravel())
            start += m
        if not rows:
            return sp.csr_matrix((0, n))
        return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(start, n))

    def hard_targets(self, offsets: dict[int, int]) -> F:
        """Right-hand side of the contact rows: the ground points where they are, 0 for touches."""
        rows = [c.points if c.b is None else np.zeros_like(c.points) for c in self.contacts if c.a in offsets]
        return np.vstack(rows) if rows else np.zeros((0, 2))

    def solve(self, sets: list[tuple[list[F], list[SECurve]]], iterations: int = ITERATIONS) -> Solve:
        """Deform the objects the flow curves reach; ``sets`` pairs flow curves (dense screen
        polylines) with the SEcurves they act on (strokes: the scene's; a centre-point's
        network: the spines it was grown from)."""
        taken = [t for flows, securves in sets for t in self.segments(flows, securves)]
        if not taken:
            return Solve({}, [], 0.0, 0.0)
        touched = {int(o) for _, owners, _ in taken for o in owners}
        comps = {self.component[o] for o in touched}
        active = [i for i in range(len(self.scene.objects)) if self.component[i] in comps]
        soft, targets = [], []
        for seg, owners, tgt in taken:
            for o in sorted(set(owners.tolist())):
                m = owners == o
                soft.append((o, seg.c[m]))
                targets.append(tgt[m])
        system, offsets, factor_ms = self._system(active, soft)
        t0 = time.perf_counter()
        hard, goal = self.hard_targets(offsets), np.vstack(targets)
        x = system.solve(hard, goal, iterations)
        reach, tilt = 1.0, self.max_tilt(x, offsets)
        if tilt > MAX_BASE_TILT_DEG:  # follow the stroke only as far as every base allows
            start = np.vstack([xy for _, xy in soft])
            lo, hi, x_lo, tilt_lo = 0.0, 1.0, system.rest.copy(), 0.0
            for _ in range(REACH_STEPS):
                mid = 0.5 * (lo + hi)
                x_mid = system.solve(hard, start + mid * (goal - start), iterations)
                t_mid = self.max_tilt(x_mid, offsets)
                if t_mid <= MAX_BASE_TILT_DEG:
                    lo, x_lo, tilt_lo = mid, x_mid, t_mid
                else:
                    hi = mid
            reach, x, tilt = lo, x_lo, tilt_lo
        solve_ms = (time.perf_counter() - t0) * 1e3
        verts = {o: x[offsets[o] : offsets[o] + len(self.embeddings[o].grid.vertices)] for o in active}
        return Solve(verts, [s for s, _, _ in taken], factor_ms, solve_ms, system, offsets, reach, tilt)

    def max_tilt(self, x: F, offsets: dict[int, int]) -> float:
        """The largest base rotation (degrees) of a planted object in the stacked grids ``x``: on screen
        (its grid's), and in 3D where Eq. 3.9 lifts enough of its points (a mesh) to fit one."""
        tilts = []
        for o in self.planted:
            if o not in offsets:
                continue
            emb = self.embeddings[o]
            v = x[offsets[o] : offsets[o] + len(emb.grid.vertices)]
            tilts.append(base_tilt_deg(emb.grid.vertices, v, _SCREEN_UP))
            if emb.obj.mesh is not None:
                rest = emb.obj.points()
                bent = lift(emb.point_rows @ v, emb.distances, self.scene.camera, self.scene.size)
                tilts.append(base_tilt_deg(rest, bent, _WORLD_UP))
        return max(tilts, default=0.0)

    def follow(self, xy: F, objects: list[int], result: Solve) -> F:
        """Screen points ``xy`` on ``objects`` carried by the solve's grids (each by the object seen there)."""
        xy = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
        out = xy.copy()
        if not result.vertices or not len(xy):
            return out
        owners = self.owners(xy, objects)
        for o in sorted(set(owners.tolist()) & set(result.vertices)):
            m = owners == o
            out[m] = self.embeddings[o].grid.rows(xy[m]) @ result.vertices[o]
        return out

    def deformed_objects(self, result: Solve) -> list[FlowObject]:
        """Every object, moved by Eq. 3.9 where the solve changed its grid."""
        out = []
        for i, (obj, emb) in enumerate(zip(self.scene.objects, self.embeddings)):
            v = result.vertices.get(i)
            out.append(obj if v is None else emb.deformed_object(v, self.scene.camera, self.scene.size))
        return out
