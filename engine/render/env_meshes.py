"""Meshes of the environment: the ground's rings, the sky's sphere, the far ridge, a cone.

Plain numpy, built once. The ground and the sky are shaded per vertex
(:mod:`engine.render.shaders_ground`), so their vertices go where the light changes:
the ground's rings are geometric (dense under the camera, sparse towards the horizon),
the sky's are close together near the horizon, where its gradient is steepest.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["ground_rings", "sky_sphere", "ridge_strip", "cone_mesh", "grid_triangles"]


def grid_triangles(rows: int, cols: int, wrap: bool = True) -> NDArray[np.int32]:
    """Triangles of a ``rows × cols`` vertex grid (row-major), columns wrapping around when ``wrap``."""
    tris = []
    span = cols if wrap else cols - 1  # the last column joins the first when wrapping
    for i in range(rows - 1):
        for k in range(span):
            k1 = (k + 1) % cols
            a, b, c, d = i * cols + k, i * cols + k1, (i + 1) * cols + k, (i + 1) * cols + k1
            tris += [(a, c, b), (b, c, d)]
    return np.array(tris, dtype=np.int32)


def ground_rings(
    rings: int = 24, segments: int = 40, inner: float = 0.002
) -> tuple[NDArray[np.float32], NDArray[np.int32]]:
    """Vertices ``[V,3]`` (unit direction x, z; radius as a fraction of the ground's extent) and triangles.

    The first ring has radius 0 (the centre under the camera), then radii grow
    geometrically from ``inner`` to 1.
    """
    radii = np.concatenate([[0.0], inner * (1.0 / inner) ** (np.arange(rings - 1) / (rings - 2))])
    angle = 2 * np.pi * np.arange(segments) / segments
    r, a = np.meshgrid(radii, angle, indexing="ij")
    verts = np.stack([np.cos(a), np.sin(a), r], axis=-1).reshape(-1, 3)
    return verts.astype(np.float32), grid_triangles(rings, segments)


def sky_sphere(segments: int = 48) -> tuple[NDArray[np.float32], NDArray[np.int32]]:
    """Unit directions ``[V,3]`` on rings of elevation, closest near the horizon, and triangles."""
    # Below -4 degrees the ground (150 m out) and the ridge's foot always cover the sky:
    # no rings there, so looking down does not rasterise a screenful of hidden sky.
    elevation = np.radians([-4, -1, 0, 2, 5, 9, 15, 24, 36, 52, 70, 90])
    angle = 2 * np.pi * np.arange(segments) / segments
    e, a = np.meshgrid(elevation, angle, indexing="ij")
    dirs = np.stack([np.cos(e) * np.cos(a), np.sin(e), np.cos(e) * np.sin(a)], axis=-1).reshape(-1, 3)
    return dirs.astype(np.float32), grid_triangles(len(elevation), segments)


def ridge_strip(segments: int = 160, seed: int = 3) -> tuple[NDArray[np.float32], NDArray[np.int32]]:
    """The far hills: per vertex unit direction x, z, height in metres, shade (0 forest, 1 snow).

    Four rows: the foot (below the ground, hidden by it), the forest's top edge, the snow
    just above it (a sharp treeline) and the crest; heights are a few sines of the azimuth with fixed phases.
    """
    rng = np.random.default_rng(seed)
    a = 2 * np.pi * np.arange(segments) / segments
    waves = ((2, 3.0), (5, 2.2), (11, 1.2), (23, 0.6))
    crest = 7.0 + sum(amp * np.sin(k * a + rng.uniform(0, 2 * np.pi)) for k, amp in waves)
    forest = 2.5 + 0.3 * crest + 0.8 * np.sin(37 * a + 1.0) * np.sin(53 * a)
    crest = np.maximum(crest, forest + 1.5)
    rows = [(np.full(segments, -6.0), 0.0), (forest, 0.0), (forest + 0.4, 0.8), (crest, 1.0)]
    verts = np.concatenate([np.stack([np.cos(a), np.sin(a), h, np.full(segments, s)], axis=-1) for h, s in rows])
    return verts.astype(np.float32), grid_triangles(len(rows), segments)


def cone_mesh(segments: int = 20, rings: int = 4) -> tuple[NDArray[np.float32], NDArray[np.int32]]:
    """A unit cone: vertices ``[V,4]`` (cos, sin of the angle round the axis; height fraction
    0 at the base to 1 at the apex; 1 on the base disc, 0 on the side) and triangles.

    The base disc closes the cone from below; the side has ``rings`` rows so the vertex
    stage can shade (snow on the upper part) and shape (a ragged skirt) along the height.
    """
    a = 2 * np.pi * np.arange(segments) / segments
    t = np.arange(rings + 1) / rings
    tt, aa = np.meshgrid(t, a, indexing="ij")
    side = np.stack([np.cos(aa), np.sin(aa), tt, np.zeros_like(tt)], axis=-1).reshape(-1, 4)
    tris = grid_triangles(rings + 1, segments)  # counter-clockwise seen from outside
    base = len(side)
    rim = np.stack([np.cos(a), np.sin(a), np.zeros(segments), np.ones(segments)], -1)
    disc = np.concatenate([[[0.0, 0.0, 0.0, 1.0]], rim])
    disc_tris = np.array([(base, base + 1 + k, base + 1 + (k + 1) % segments) for k in range(segments)], dtype=np.int32)
    return (np.concatenate([side, disc]).astype(np.float32), np.concatenate([tris, disc_tris]).astype(np.int32))
