"""Triangle meshes in a flow scene: their footprint, and reading one from a glTF binary.

§3.5.1 embeds "a 3D object with vertices v_1 … v_N": any triangle mesh, not only our
spheres and capsules. A :class:`TriMesh` is such an object's surface; Eq. 3.9 lifts every
one of its vertices through the object's deformed grid, so one mesh bends along a stroke
(a capsule, lifted at its two end points only, can only move and turn).

Its footprint and depth map (what §3.3.1 samples and the grid is laid over) come from a
small software z-buffer: each triangle, projected, covers the stride-spaced pixel centres
inside it, at the distance along each pixel's ray (view depth interpolated perspective-correctly). :func:`read_glb_mesh` is the
one validation boundary for a mesh read from a file (a ``.glb`` prop).
"""

from __future__ import annotations

import json
import struct
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from engine.camera import Camera

__all__ = ["MAX_MESH_TRIANGLES", "MAX_MESH_VERTICES", "MeshError", "TriMesh", "rasterize_mesh", "read_glb_mesh"]

from engine.arrays import F64 as F
from engine.arrays import I64 as I

#: renderer's joint texture is one row per joint (GL's smallest guaranteed texture side is 16384).
MAX_MESH_VERTICES = 8192
MAX_MESH_TRIANGLES = 4 * MAX_MESH_VERTICES
MAX_GLB_BYTES = 16 * 1024 * 1024


class MeshError(ValueError):
    """A mesh that cannot be used (one line says why)."""


@dataclass
class TriMesh:
    """Vertices ``[V, 3]`` (world metres), triangles ``[T, 3]`` into them, and an sRGB colour per
    triangle (``face_colors`` ``[T, 3]``; absent: ``color`` for all)."""

    vertices: F
    faces: I
    color: tuple[float, float, float] = (0.6, 0.6, 0.6)
    face_colors: F | None = None

    def __post_init__(self) -> None:
        self.vertices = np.asarray(self.vertices, dtype=np.float64).reshape(-1, 3)
        self.faces = np.asarray(self.faces, dtype=np.int64).reshape(-1, 3)
        v, t = len(self.vertices), len(self.faces)
        if not 3 <= v <= MAX_MESH_VERTICES or not 1 <= t <= MAX_MESH_TRIANGLES:
            raise MeshError(
                f"a flow mesh needs 3..{MAX_MESH_VERTICES} vertices and 1..{MAX_MESH_TRIANGLES} "
                f"triangles, not {v} and {t}"
            )
        if not np.isfinite(self.vertices).all():
            raise MeshError("a mesh vertex is not finite")
        if self.faces.min() < 0 or self.faces.max() >= v:
            raise MeshError("a mesh triangle indexes a vertex that does not exist")
        if self.face_colors is not None:
            self.face_colors = np.asarray(self.face_colors, dtype=np.float64).reshape(-1, 3)
            if len(self.face_colors) != t or not ((self.face_colors >= 0) & (self.face_colors <= 1)).all():
                raise MeshError("a mesh needs one colour in [0, 1] per triangle")

    def colors(self) -> F:
        """``[T, 3]`` every triangle's sRGB colour."""
        return self.face_colors if self.face_colors is not None else np.tile(self.color, (len(self.faces), 1))

    def with_vertices(self, vertices: F) -> TriMesh:
        """The same triangles and colours over moved vertices."""
        return TriMesh(np.array(vertices, dtype=np.float64), self.faces, self.color, self.face_colors)


def rasterize_mesh(
    mesh: TriMesh, camera: Camera, size: tuple[int, int], x0: int, y0: int, stride: int, shape: tuple[int, int]
) -> F:
    """Eye distance ``[ny, nx]`` of the mesh at pixel centres ``(x0 + i·stride, y0 + j·stride)`` (inf: uncovered)."""
    from authoring.flowcurves.scene import pixel_rays

    ny, nx = shape
    depth = np.full(shape, np.inf)
    xy = camera.project(mesh.vertices, size[0], size[1])
    z = (mesh.vertices - camera.eye) @ camera.forward  # view depth: its inverse is linear on screen
    ahead = z > 1e-3
    for a, b, c in mesh.faces:
        if not (ahead[a] and ahead[b] and ahead[c]):
            continue
        p = xy[[a, b, c]]
        lo = np.floor((p.min(axis=0) - [x0, y0]) / stride).astype(np.int64)
        hi = np.ceil((p.max(axis=0) - [x0, y0]) / stride).astype(np.int64)
        i0, j0 = max(lo[0], 0), max(lo[1], 0)
        i1, j1 = min(hi[0], nx - 1), min(hi[1], ny - 1)
        if i1 < i0 or j1 < j0:
            continue
        gi, gj = np.meshgrid(np.arange(i0, i1 + 1), np.arange(j0, j1 + 1))
        px = np.c_[x0 + gi.ravel() * stride, y0 + gj.ravel() * stride].astype(np.float64)
        v0, v1 = p[1] - p[0], p[2] - p[0]
        det = v0[0] * v1[1] - v0[1] * v1[0]
        if abs(det) < 1e-12:
            continue
        d = px - p[0]
        l1 = (d[:, 0] * v1[1] - d[:, 1] * v1[0]) / det
        l2 = (v0[0] * d[:, 1] - v0[1] * d[:, 0]) / det
        inside = (l1 >= -1e-9) & (l2 >= -1e-9) & (l1 + l2 <= 1 + 1e-9)
        if not inside.any():
            continue
        l1, l2 = l1[inside], l2[inside]
        zp = 1.0 / ((1 - l1 - l2) / z[a] + l1 / z[b] + l2 / z[c])  # perspective-correct view depth
        hit = zp / (pixel_rays(camera, px[inside], size) @ camera.forward)  # the distance along the pixel's ray
        jj, ii = gj.ravel()[inside], gi.ravel()[inside]
        np.minimum.at(depth, (jj, ii), hit)
    return depth


def _accessor(doc: dict, blob: bytes, index: object, width: int) -> NDArray[np.float64]:
    """One accessor of an embedded-buffer GLB as ``[count, width]`` (float32 or unsigned integer data)."""
    kinds = {5126: "<f4", 5125: "<u4", 5123: "<u2", 5121: "u1"}
    accessors = doc.get("accessors", [])
    if not isinstance(index, int) or not 0 <= index < len(accessors):
        raise MeshError("an accessor index is out of range")
    acc = accessors[index]
    views = doc.get("bufferViews", [])
    view_i, count, ctype = acc.get("bufferView"), acc.get("count"), acc.get("componentType")
    if not isinstance(view_i, int) or not 0 <= view_i < len(views) or ctype not in kinds:
        raise MeshError("an accessor has no usable buffer view or component type")
    if not isinstance(count, int) or not 0 < count <= MAX_MESH_TRIANGLES * 3:
        raise MeshError("an accessor count is out of range")
    view = views[view_i]
    start = int(view.get("byteOffset", 0)) + int(acc.get("byteOffset", 0))
    dtype = np.dtype(kinds[ctype])
    stride = int(view.get("byteStride", dtype.itemsize * width))
    end = start + stride * (count - 1) + dtype.itemsize * width
    if view.get("buffer", 0) != 0 or start < 0 or end > len(blob) or stride < dtype.itemsize * width:
        raise MeshError("an accessor reads outside the file's buffer")
    rows = np.ndarray((count, width), dtype=dtype, buffer=blob, offset=start, strides=(stride, dtype.itemsize))
    return rows.astype(np.float64)


def read_glb_mesh(path: Path, color: tuple[float, float, float] = (0.6, 0.6, 0.6)) -> TriMesh:
    """Every triangle primitive of a ``.glb`` file's meshes, at their nodes' translations, as one mesh.

    Node rotations and scales are applied too (their 4x4 ``matrix`` or TRS); only embedded buffers
    are read (a prop is one file). Any fault is one :class:`MeshError` line.
    """
    from engine.io.gltf import GltfError, parse_glb

    try:
        raw = Path(path).read_bytes()
    except OSError as exc:
        raise MeshError(f"{path}: {exc.strerror or exc}") from None
    if len(raw) > MAX_GLB_BYTES:
        raise MeshError(f"{path}: larger than {MAX_GLB_BYTES} bytes")
    try:
        doc, blob = parse_glb(raw, str(path))
    except (GltfError, ValueError, struct.error, json.JSONDecodeError) as exc:
        raise MeshError(f"{path}: {str(exc)[:120]}") from None
    if blob is None:
        raise MeshError(f"{path}: has no embedded buffer")
    verts: list[F] = []
    faces: list[I] = []
    meshes = doc.get("meshes", [])
    try:
        for node in doc.get("nodes", []):
            m = node.get("mesh")
            if m is None:
                continue
            if not isinstance(m, int) or not 0 <= m < len(meshes):
                raise MeshError("a node names a mesh that does not exist")
            xf = _node_matrix(node)
            for prim in meshes[m].get("primitives", []):
                if prim.get("mode", 4) != 4 or "POSITION" not in prim.get("attributes", {}):
                    continue
                pos = _accessor(doc, blob, prim["attributes"]["POSITION"], 3)
                idx = (
                    _accessor(doc, blob, prim["indices"], 1).ravel()
                    if "indices" in prim
                    else np.arange(len(pos), dtype=np.float64)
                )
                if len(idx) % 3 or (len(idx) and idx.max() >= len(pos)):
                    raise MeshError("a primitive's indices are not whole triangles of its vertices")
                base = sum(len(v) for v in verts)
                verts.append(pos @ xf[:3, :3].T + xf[:3, 3])
                faces.append(idx.astype(np.int64).reshape(-1, 3) + base)
    except MeshError as exc:
        raise MeshError(f"{path}: {exc}") from None
    except (KeyError, TypeError, AttributeError, ValueError) as exc:
        raise MeshError(f"{path}: malformed mesh data ({type(exc).__name__})") from None
    if not verts:
        raise MeshError(f"{path}: has no triangle mesh")
    try:
        return TriMesh(np.vstack(verts), np.vstack(faces), color)
    except MeshError as exc:
        raise MeshError(f"{path}: {exc}") from None


def _node_matrix(node: dict) -> F:
    """A node's local transform (its parents are not composed: a prop is a flat list of nodes)."""
    if "matrix" in node:
        m = np.asarray(node["matrix"], dtype=np.float64)
        if m.shape != (16,) or not np.isfinite(m).all():
            raise MeshError("a node matrix is not 16 finite numbers")
        return m.reshape(4, 4).T
    t = np.asarray(node.get("translation", [0, 0, 0]), dtype=np.float64)
    q = np.asarray(node.get("rotation", [0, 0, 0, 1]), dtype=np.float64)
    s = np.asarray(node.get("scale", [1, 1, 1]), dtype=np.float64)
    if t.shape != (3,) or q.shape != (4,) or s.shape != (3,) or not np.isfinite(np.r_[t, q, s]).all():
        raise MeshError("a node's translation, rotation or scale is malformed")
    x, y, z, w = q / max(float(np.linalg.norm(q)), 1e-12)
    r = np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )
    out = np.eye(4)
    out[:3, :3] = r * s
    out[:3, 3] = t
    return out
