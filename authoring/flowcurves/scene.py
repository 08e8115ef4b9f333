"""A flow scene: static objects made of spheres, capsules and triangle meshes, seen from one camera.

Chapter 3 works on raw geometry seen from a viewpoint. Much of our scenery is drawn from
spheres and capsules (trees, rocks), so an object here is a list of those primitives and,
optionally, one triangle mesh (:class:`~authoring.flowcurves.mesh.TriMesh`: a crystal tree,
an island, a glTF prop); its screen footprint and depth map come from casting one ray per
pixel (at a stride) against the primitives and z-buffering the mesh's triangles — the
"depth map pixels whose depth is lower than 1" that §3.3.1 samples. The ground (y = 0) is not an object: it never deforms, so what rests
on it stays planted (§3.5.3's layout constraints).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from authoring.flowcurves.mesh import TriMesh, rasterize_mesh
from engine.camera import Camera

__all__ = ["Primitive", "FlowObject", "FlowScene", "Raster", "rasterize", "pixel_rays", "project"]

from engine.arrays import F64 as F


@dataclass
class Primitive:
    """A sphere (``a == b``) or a capsule from ``a`` to ``b``, with its radius and colour."""

    a: F
    b: F
    radius: float
    color: tuple[float, float, float] = (0.6, 0.6, 0.6)

    @property
    def is_sphere(self) -> bool:
        """Whether both ends coincide."""
        return bool(np.allclose(self.a, self.b))


@dataclass
class FlowObject:
    """One deformable object; ``group`` names the assembly it belongs to (a tree's parts).

    Its primitives and its mesh (either may be absent, not both) are what Eq. 3.9 lifts.
    """

    name: str
    group: str
    primitives: list[Primitive]
    mesh: TriMesh | None = None

    def __post_init__(self) -> None:
        if not self.primitives and self.mesh is None:
            raise ValueError(f"object {self.name!r} has neither primitives nor a mesh")

    def points(self) -> F:
        """``[2P + V, 3]`` the primitives' end points, then the mesh's vertices (the "vertices" Eq. 3.9 moves)."""
        ends = np.array([p for prim in self.primitives for p in (prim.a, prim.b)], dtype=np.float64).reshape(-1, 3)
        return ends if self.mesh is None else np.vstack([ends, self.mesh.vertices])

    def with_points(self, pts: F) -> FlowObject:
        """A copy whose primitive end points and mesh vertices are ``pts`` (radii, triangles, colours kept)."""
        prims = [
            Primitive(np.array(pts[2 * i]), np.array(pts[2 * i + 1]), p.radius, p.color)
            for i, p in enumerate(self.primitives)
        ]
        mesh = None if self.mesh is None else self.mesh.with_vertices(pts[2 * len(self.primitives) :])
        return FlowObject(self.name, self.group, prims, mesh)


@dataclass
class FlowScene:
    """Objects, the camera they are seen from and the viewport size in pixels."""

    name: str
    objects: list[FlowObject]
    camera: Camera
    size: tuple[int, int] = (1280, 720)
    ground: bool = True
    extras: dict[str, object] = field(default_factory=dict)


@dataclass
class Raster:
    """An object's footprint: ``mask[j, i]`` covers pixel ``(x0 + i·stride, y0 + j·stride)``."""

    x0: int
    y0: int
    stride: int
    mask: NDArray[np.bool_]
    depth: F

    def pixels(self) -> F:
        """``[N, 2]`` covered pixel positions."""
        j, i = np.nonzero(self.mask)
        return np.c_[self.x0 + i * self.stride, self.y0 + j * self.stride].astype(np.float64)

    def edge_pixels(self) -> F:
        """Covered pixels with an uncovered 4-neighbour (the footprint's outline)."""
        m = np.pad(self.mask, 1)
        inner = m[1:-1, 1:-1] & m[:-2, 1:-1] & m[2:, 1:-1] & m[1:-1, :-2] & m[1:-1, 2:]
        j, i = np.nonzero(self.mask & ~inner)
        return np.c_[self.x0 + i * self.stride, self.y0 + j * self.stride].astype(np.float64)

    def depth_at(self, xy: F) -> F:
        """Hit distance at pixels ``[N, 2]`` (inf where uncovered or outside)."""
        i = np.rint((xy[:, 0] - self.x0) / self.stride).astype(np.int64)
        j = np.rint((xy[:, 1] - self.y0) / self.stride).astype(np.int64)
        ok = (i >= 0) & (j >= 0) & (i < self.mask.shape[1]) & (j < self.mask.shape[0])
        out = np.full(len(xy), np.inf)
        out[ok] = np.where(self.mask[j[ok], i[ok]], self.depth[j[ok], i[ok]], np.inf)
        return out


def project(camera: Camera, points: F, size: tuple[int, int]) -> F:
    """Pixel positions ``[N, 2]`` of world points."""
    return camera.project(points, size[0], size[1])


def pixel_rays(camera: Camera, xy: F, size: tuple[int, int]) -> F:
    """Unit world directions ``[N, 3]`` of the rays through pixels ``xy`` (top-left origin)."""
    w, h = size
    t = np.tan(np.radians(camera.fov_y) / 2.0)
    nx = 2.0 * xy[:, 0] / w - 1.0
    ny = 1.0 - 2.0 * xy[:, 1] / h
    d = np.c_[nx * t * w / h, ny * t, -np.ones(len(xy))] @ camera.rotation.T
    return d / np.linalg.norm(d, axis=1, keepdims=True)


def _hit_sphere(ro: F, rd: F, c: F, r: float) -> F:
    oc = ro - c
    b = rd @ oc
    h = b * b - (oc @ oc - r * r)
    with np.errstate(invalid="ignore"):
        t = -b - np.sqrt(h)
    return np.where((h >= 0) & (t > 0), t, np.inf)


def _hit_capsule(ro: F, rd: F, a: F, b: F, r: float) -> F:
    """Ray–capsule distance (Quilez's closed form), vectorised over ray directions."""
    ba, oa = b - a, ro - a
    baba, bard, baoa = ba @ ba, rd @ ba, ba @ oa
    rdoa, oaoa = rd @ oa, oa @ oa
    qa = baba - bard * bard
    qb = baba * rdoa - baoa * bard
    qc = baba * oaoa - baoa * baoa - r * r * baba
    h = qb * qb - qa * qc
    with np.errstate(invalid="ignore", divide="ignore"):
        t = (-qb - np.sqrt(h)) / qa
    y = baoa + t * bard
    body = (h >= 0) & (y > 0) & (y < baba) & (t > 0)
    caps = np.minimum(_hit_sphere(ro, rd, a, r), _hit_sphere(ro, rd, b, r))
    return np.where(body, t, caps)


def hit_distance(prims: list[Primitive], ro: F, rd: F) -> F:
    """Nearest hit distance of each ray against the primitives (inf: missed)."""
    t = np.full(len(rd), np.inf)
    for p in prims:
        hit = _hit_sphere(ro, rd, p.a, p.radius) if p.is_sphere else _hit_capsule(ro, rd, p.a, p.b, p.radius)
        t = np.minimum(t, hit)
    return t


def screen_bounds(obj: FlowObject, camera: Camera, size: tuple[int, int]) -> tuple[F, F]:
    """Pixel bounding box (lo, hi) of an object: its primitives' ends padded by their projected radii,
    its mesh vertices by two pixels."""
    pts = obj.points()
    radii = np.r_[np.repeat([p.radius for p in obj.primitives], 2), np.zeros(len(pts) - 2 * len(obj.primitives))]
    xy = project(camera, pts, size)
    dist = np.linalg.norm(pts - camera.eye, axis=1)
    focal = size[1] / (2.0 * np.tan(np.radians(camera.fov_y) / 2.0))
    pad = radii * focal / np.maximum(dist - radii, 1e-3) + 2.0
    return (xy - pad[:, None]).min(axis=0), (xy + pad[:, None]).max(axis=0)


def rasterize(obj: FlowObject, camera: Camera, size: tuple[int, int], stride: int = 2) -> Raster:
    """Cast rays through the object's screen box (and z-buffer its mesh); the hits are its footprint and depth map."""
    lo, hi = screen_bounds(obj, camera, size)
    x0, y0 = int(np.floor(lo[0])), int(np.floor(lo[1]))
    nx = max(1, int(np.ceil((hi[0] - x0) / stride)) + 1)
    ny = max(1, int(np.ceil((hi[1] - y0) / stride)) + 1)
    gx, gy = np.meshgrid(x0 + stride * np.arange(nx), y0 + stride * np.arange(ny))
    xy = np.c_[gx.ravel(), gy.ravel()].astype(np.float64)
    t = hit_distance(obj.primitives, camera.eye, pixel_rays(camera, xy, size)).reshape(ny, nx)
    if obj.mesh is not None:
        t = np.minimum(t, rasterize_mesh(obj.mesh, camera, size, x0, y0, stride, (ny, nx)))
    return Raster(x0, y0, stride, np.isfinite(t), t)
