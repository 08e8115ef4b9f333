"""The 2D grid embedding of an object (§3.5.1) and the 3D reconstruction of Eq. 3.9.

Movement edits are screen-space refinements, so each object is deformed through a
triangle grid laid over its screen bounding box at 15 px (each square cell split in
two), keeping only the triangles its footprint covers. Anything attached to the
object — its primitive end points, its SEcurve samples, its contact points — is held
as barycentric coordinates of one grid triangle (the containing one, or for a point
just outside, the nearest one, extrapolated), so it follows the grid linearly: after
deforming the grid vertices ``x_g`` into ``x'_g``, a point is ``φ(x'_g)``, and a 3D
vertex comes back at its old distance from the eye along the ray through that pixel
(Eq. 3.9; we keep the distance to the eye rather than along the view axis, so an
undeformed grid gives every vertex back exactly).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from authoring.flowcurves.scene import FlowObject, Raster, pixel_rays
from engine.camera import Camera

__all__ = ["Grid", "build_grid", "Embedding", "GRID_SPACING", "lift"]

from engine.arrays import F64 as F
from engine.arrays import I64 as I

GRID_SPACING = 15.0


@dataclass
class Grid:
    """Rest vertices ``[V, 2]`` (pixels) and triangles ``[T, 3]`` of one object's embedding."""

    vertices: F
    triangles: I

    def locate(self, xy: F) -> tuple[I, F]:
        """Triangle and barycentric coordinates of each point (nearest triangle, extrapolated, outside)."""
        tri = self.vertices[self.triangles]
        a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
        v0, v1 = b - a, c - a
        det = v0[:, 0] * v1[:, 1] - v0[:, 1] * v1[:, 0]
        d = xy[:, None, :] - a[None]
        l1 = (d[..., 0] * v1[:, 1] - d[..., 1] * v1[:, 0]) / det
        l2 = (v0[:, 0] * d[..., 1] - v0[:, 1] * d[..., 0]) / det
        bary = np.stack([1 - l1 - l2, l1, l2], axis=-1)
        outside = np.clip(-bary, 0, None).sum(axis=-1)  # 0 inside; grows with the distance outside
        centre = tri.mean(axis=1)
        score = outside * 1e3 + np.linalg.norm(xy[:, None, :] - centre[None], axis=-1) * 1e-3
        best = np.argmin(score, axis=1)
        return best, bary[np.arange(len(xy)), best]

    def rows(self, xy: F) -> sp.csr_matrix:
        """``[N, V]`` sparse map from grid vertices to the points ``xy``."""
        t, bary = self.locate(np.asarray(xy, dtype=np.float64).reshape(-1, 2))
        cols = self.triangles[t]
        n = len(t)
        return sp.csr_matrix((bary.ravel(), (np.repeat(np.arange(n), 3), cols.ravel())), shape=(n, len(self.vertices)))


def build_grid(raster: Raster, spacing: float = GRID_SPACING) -> Grid:
    """Tessellate the raster's box at ``spacing`` and keep the triangles its pixels fall in."""
    px = raster.pixels()
    if len(px) == 0:
        raise ValueError("the object covers no pixel from this camera")
    lo = px.min(axis=0) - spacing * 0.5
    nx = int(np.ceil((px[:, 0].max() - lo[0]) / spacing)) + 1
    ny = int(np.ceil((px[:, 1].max() - lo[1]) / spacing)) + 1
    ci = np.clip(((px[:, 0] - lo[0]) // spacing).astype(np.int64), 0, nx - 1)
    cj = np.clip(((px[:, 1] - lo[1]) // spacing).astype(np.int64), 0, ny - 1)
    fx = (px[:, 0] - lo[0]) / spacing - ci
    fy = (px[:, 1] - lo[1]) / spacing - cj
    upper = (fx + fy < 1.0).astype(np.int64)  # cell split along its anti-diagonal: 1 = upper-left half
    used = np.zeros((ny, nx, 2), dtype=bool)
    used[cj, ci, upper] = True
    vid = lambda i, j: j * (nx + 1) + i  # noqa: E731 - a local index formula
    tris = []
    for j, i, half in zip(*np.nonzero(used)):
        if half:
            tris.append((vid(i, j), vid(i + 1, j), vid(i, j + 1)))
        else:
            tris.append((vid(i + 1, j), vid(i + 1, j + 1), vid(i, j + 1)))
    tri = np.array(tris, dtype=np.int64)
    keep, tri = np.unique(tri, return_inverse=True)
    tri = tri.reshape(-1, 3)
    gx, gy = keep % (nx + 1), keep // (nx + 1)
    verts = np.c_[lo[0] + gx * spacing, lo[1] + gy * spacing]
    return Grid(verts, tri)


@dataclass
class Embedding:
    """An object's grid and its primitive end points, held barycentrically plus their eye distance."""

    obj: FlowObject
    raster: Raster
    grid: Grid
    point_rows: sp.csr_matrix
    distances: F

    @classmethod
    def of(
        cls, obj: FlowObject, raster: Raster, camera: Camera, size: tuple[int, int], spacing: float = GRID_SPACING
    ) -> Embedding:
        grid = build_grid(raster, spacing)
        pts = obj.points()
        xy = camera.project(pts, size[0], size[1])
        return cls(obj, raster, grid, grid.rows(xy), np.linalg.norm(pts - camera.eye, axis=1))

    def deformed_object(self, vertices: F, camera: Camera, size: tuple[int, int]) -> FlowObject:
        """The object with its end points moved by the deformed grid ``vertices`` (Eq. 3.9)."""
        return self.obj.with_points(lift(self.point_rows @ vertices, self.distances, camera, size))


def lift(xy: F, distances: F, camera: Camera, size: tuple[int, int]) -> F:
    """Eq. 3.9: ``v' = eye + d · x_dir(x')`` for screen positions ``xy`` and eye distances ``d``."""
    return camera.eye + distances[:, None] * pixel_rays(camera, np.asarray(xy, dtype=np.float64), size)
