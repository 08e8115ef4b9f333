"""Level of detail for capsules and spheres: as few facets as the picture allows.

On llvmpipe the vertex stage runs on one thread, and in the snowman field it cost more
than the shading of the balls: 77 spheres of 280 vertices each, most of them a few
dozen pixels across. Each capsule or sphere is therefore drawn with the coarsest mesh
whose outline stays within about a pixel of the true one. A circle of ``r`` pixels drawn
as an ``s``-gon is off by ``r (1 - cos(pi / s))`` at its worst, which gives each level the
largest on-screen radius it may draw; the finest level takes everything bigger. Rings
per hemisphere follow the same angular step (about ``s / 4``), so the outline seen from
the side is as smooth as the one seen along the axis.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from engine.render.meshes import capsule_mesh

__all__ = [
    "CAPSULE_LEVELS",
    "SPHERE_LEVELS",
    "LEVELS",
    "LIMITS",
    "SILHOUETTE_ERROR_PX",
    "level_limits",
    "choose_levels",
    "choose_levels_orthographic",
    "level_meshes",
]

CAPSULE_LEVELS: tuple[tuple[int, int], ...] = ((6, 2), (8, 2), (12, 3), (16, 4), (24, 6))
"""(segments around, rings per end cap) from coarse to fine."""
SPHERE_LEVELS: tuple[tuple[int, int], ...] = ((10, 3), (14, 4), (20, 6), (28, 8))
SILHOUETTE_ERROR_PX = 1.0
_NEAREST_M = 0.05  # a camera inside a shape takes the finest level, not a division by zero


def level_limits(levels: tuple[tuple[int, int], ...], error_px: float = SILHOUETTE_ERROR_PX) -> NDArray[np.float64]:
    """Largest on-screen radius in pixels each level but the finest may draw."""
    return np.array([error_px / (1.0 - math.cos(math.pi / segments)) for segments, _ in levels[:-1]])


LEVELS = {"capsules": CAPSULE_LEVELS, "spheres": SPHERE_LEVELS}
"""The levels of each kind of round solid, by its RenderScene name."""
LIMITS = {kind: level_limits(levels) for kind, levels in LEVELS.items()}
"""Each kind's :func:`level_limits`, computed once."""


def level_meshes(kind: str) -> list[tuple[NDArray[np.float32], NDArray[np.int32]]]:
    """The unit mesh of each level of ``kind`` ("capsules" or "spheres": no cylinder band)."""
    return [capsule_mesh(segments, rings, band=kind == "capsules") for segments, rings in LEVELS[kind]]


def choose_levels(
    rows: NDArray[np.float32], eye: NDArray[np.float64], px_per_metre: float, limits: NDArray[np.float64]
) -> NDArray[np.intp]:
    """The level index for each capsule row (ends ``a``, ``b`` in columns 0-5, radius in 6).

    The on-screen radius is taken at the capsule's point nearest the eye, so a long
    capsule pointing at the camera gets the detail its near end needs.
    """
    a, b, r = rows[:, 0:3].astype(np.float64), rows[:, 3:6].astype(np.float64), rows[:, 6].astype(np.float64)
    axis = b - a
    length2 = np.einsum("ij,ij->i", axis, axis)
    t = np.clip(np.einsum("ij,ij->i", eye - a, axis) / np.maximum(length2, 1e-12), 0.0, 1.0)
    distance = np.linalg.norm(a + t[:, None] * axis - eye, axis=1) - r
    radius_px = r * px_per_metre / np.maximum(distance, _NEAREST_M)
    return np.searchsorted(limits, radius_px)


def choose_levels_orthographic(
    rows: NDArray[np.float32], px_per_metre: float, limits: NDArray[np.float64]
) -> NDArray[np.intp]:
    """The level index for each capsule row seen through an orthographic projection (the
    sun's shadow map), where the size on screen does not depend on distance."""
    return np.searchsorted(limits, rows[:, 6].astype(np.float64) * px_per_metre)
