"""Unit meshes the renderer instances: capsule, sphere, box, and helper quads.

Why one capsule mesh serves every capsule: each vertex stores a unit direction and
the end it belongs to (0 = ``a``, 1 = ``b``). The vertex shader puts it at
``mix(a, b, end) + radius * direction`` in the capsule's own frame, which gives an exact
capsule of any length and radius (scaling a mesh would squash the hemispheres). A sphere
is the same mesh without its cylinder band. Triangles wind counter-clockwise seen from
outside, so back-face culling works and front-face culling draws inflated outlines.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["capsule_mesh", "sphere_mesh", "box_mesh"]


def _orient_outward(
    pos: NDArray[np.float64], tris: NDArray[np.int64], centre_of: NDArray[np.float64]
) -> NDArray[np.int64]:
    """Flip triangles whose winding faces inwards (normal points towards ``centre_of``)."""
    p0, p1, p2 = pos[tris[:, 0]], pos[tris[:, 1]], pos[tris[:, 2]]
    n = np.cross(p1 - p0, p2 - p0)
    outward = np.einsum("ij,ij->i", n, (p0 + p1 + p2) / 3.0 - centre_of) >= 0
    tris = tris.copy()
    tris[~outward] = tris[~outward][:, [0, 2, 1]]
    return tris


def _hemisphere_rings(segments: int, rings: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Unit directions and end flags: north cap (end 1) from pole to equator, then south (end 0)."""
    dirs, ends = [], []
    for half, end in ((1.0, 1.0), (-1.0, 0.0)):
        for i in range(rings + 1):
            lat = (np.pi / 2) * (1.0 - i / rings)  # pole -> equator
            for k in range(segments):
                lon = 2 * np.pi * k / segments
                dirs.append((np.cos(lat) * np.cos(lon), half * np.sin(lat), np.cos(lat) * np.sin(lon)))
                ends.append(end)
    return np.array(dirs), np.array(ends)


def _grid_tris(row0: int, row1: int, segments: int) -> list[tuple[int, int, int]]:
    out = []
    for k in range(segments):
        k1 = (k + 1) % segments
        a, b, c, d = row0 + k, row0 + k1, row1 + k, row1 + k1
        out += [(a, c, b), (b, c, d)]
    return out


def capsule_mesh(
    segments: int = 12, rings: int = 3, *, band: bool = True
) -> tuple[NDArray[np.float32], NDArray[np.int32]]:
    """Vertices ``[V,4]`` (unit direction xyz, end flag) and triangle indices ``[T,3]``.

    With ``band=False`` the cylinder between the caps is left out: a sphere mesh.
    """
    dirs, ends = _hemisphere_rings(segments, rings)
    per_cap = (rings + 1) * segments
    tris: list[tuple[int, int, int]] = []
    for cap in (0, per_cap):
        for i in range(rings):
            tris += _grid_tris(cap + i * segments, cap + (i + 1) * segments, segments)
    equator_n, equator_s = rings * segments, per_cap + rings * segments
    if band:
        tris += _grid_tris(equator_n, equator_s, segments)
    # Orientation test on the geometry of a capsule stretched along Y (ends at y=+-1).
    geo = dirs + np.c_[np.zeros(len(ends)), 2.0 * ends - 1.0, np.zeros(len(ends))]
    t = np.array(tris, dtype=np.int64)
    t = _orient_outward(geo, t, np.zeros(3))
    # Outward test is ambiguous on degenerate pole triangles; those have zero area and never show.
    verts = np.c_[dirs, ends].astype(np.float32)
    return verts, t.astype(np.int32)


def sphere_mesh(segments: int = 20, rings: int = 6) -> tuple[NDArray[np.float32], NDArray[np.int32]]:
    """A capsule mesh without its cylinder band; both caps meet at the equator."""
    return capsule_mesh(segments, rings, band=False)


def box_mesh() -> tuple[NDArray[np.float32], NDArray[np.int32]]:
    """A unit cube ``[-1,1]^3``: vertices ``[24,6]`` (position, face normal) and ``[12,3]`` triangles."""
    verts: list[NDArray[np.float64]] = []
    tris: list[tuple[int, int, int]] = []
    for axis in range(3):
        for sign in (-1.0, 1.0):
            n = np.zeros(3)
            n[axis] = sign
            u = np.zeros(3)
            u[(axis + 1) % 3] = 1.0
            v = np.cross(n, u)
            base = len(verts)
            for du, dv in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                verts.append(np.r_[n + du * u + dv * v, n])
            tris += [(base, base + 1, base + 2), (base, base + 2, base + 3)]
    vv = np.array(verts)
    t = _orient_outward(vv[:, :3], np.array(tris, dtype=np.int64), np.zeros(3))
    return vv.astype(np.float32), t.astype(np.int32)
