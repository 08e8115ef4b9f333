"""Subjective curve elements of a scene (§3.3): which curve stands for which objects.

For each group of objects (a tree's trunk, tiers and snow caps; a lone rock) both a
principal curve (§3.3.1) and an abstract contour (§3.3.2) are computed from the group's
footprint; the thinness test keeps the principal curve for thin shapes, the contour for
the others. Groups whose principal curves run close to one another also get one contour
around them all (the thesis' four poles). The user may draw more (``SECurve.user``).

Every SEcurve of an elongated group also keeps its principal curve (``spine``): the
centre-point network (§3.4.2) extends and averages *open* curves, which a contour is
not, and its curves then take those spines (a round rock has no direction and no spine).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from authoring.flowcurves.contours import THIN, abstract_contour, thinness
from authoring.flowcurves.principal import principal_curve
from authoring.flowcurves.scene import FlowScene, Raster

__all__ = ["SECurve", "compute_securves", "GROUP_DISTANCE"]

from engine.arrays import F64 as F

GROUP_DISTANCE = 40.0
#: A footprint this many times longer than wide has a direction worth a spine (a rock has none).
ELONGATED = 1.4


@dataclass
class SECurve:
    """A polyline on screen, closed or not, and the indices of the objects it stands for."""

    points: F
    closed: bool
    kind: str
    objects: list[int]
    spine: F | None = None
    thinness: float = field(default=float("nan"))

    @classmethod
    def user(cls, points: ArrayLike, objects: list[int]) -> SECurve:
        """An SEcurve drawn by the user over the given objects."""
        p = np.asarray(points, dtype=np.float64)
        return cls(p, False, "user", list(objects), spine=p)


def _groups(scene: FlowScene) -> dict[str, list[int]]:
    groups: dict[str, list[int]] = {}
    for i, obj in enumerate(scene.objects):
        groups.setdefault(obj.group, []).append(i)
    return groups


def _union(rasters: list[Raster], members: list[int]) -> tuple[F, F]:
    pixels = np.vstack([rasters[i].pixels() for i in members])
    edges = np.vstack([rasters[i].edge_pixels() for i in members])
    return pixels, edges


def _elongation(pixels: F) -> float:
    """Ratio of the footprint's principal spreads (1 for a disc)."""
    ev = np.linalg.eigvalsh(np.cov((pixels - pixels.mean(axis=0)).T))
    return float(np.sqrt(ev[-1] / max(ev[0], 1e-9)))


def _curve_distance(a: F, b: F) -> float:
    return float(np.sqrt(((a[:, None, :] - b[None]) ** 2).sum(axis=-1)).min())


def compute_securves(
    scene: FlowScene, rasters: list[Raster], progress: Callable[[int, int, str], None] | None = None
) -> list[SECurve]:
    """The scene's SEcurves, one per group plus group contours, in group order (repeatable)."""
    out: list[SECurve] = []
    spines: list[tuple[F, list[int]]] = []
    groups = _groups(scene)
    for k, (name, members) in enumerate(groups.items()):
        if progress is not None:
            progress(k, len(groups), name)
        pixels, edges = _union(rasters, members)
        if len(pixels) < 3:
            continue
        principal = principal_curve(pixels)
        spine = principal.sample(48)
        contour = abstract_contour(edges)
        thin = thinness(principal, contour)
        if thin < THIN:
            out.append(SECurve(spine, False, "principal", members, spine, thin))
            spines.append((spine, members))
        else:
            out.append(
                SECurve(
                    contour.sample(96),
                    True,
                    "contour",
                    members,
                    spine if _elongation(pixels) >= ELONGATED else None,
                    thin,
                )
            )
    out.extend(_group_contours(spines, rasters))
    return out


def _group_contours(spines: list[tuple[F, list[int]]], rasters: list[Raster]) -> list[SECurve]:
    parent = list(range(len(spines)))

    def root(a: int) -> int:
        while parent[a] != a:
            a = parent[a]
        return a

    for i in range(len(spines)):
        for j in range(i + 1, len(spines)):
            if _curve_distance(spines[i][0], spines[j][0]) < GROUP_DISTANCE:
                parent[root(j)] = root(i)
    clusters: dict[int, list[int]] = {}
    for i in range(len(spines)):
        clusters.setdefault(root(i), []).append(i)
    out = []
    for members in clusters.values():
        if len(members) < 2:
            continue
        objects = sorted(o for m in members for o in spines[m][1])
        contour = abstract_contour(_union(rasters, objects)[1])
        out.append(SECurve(contour.sample(96), True, "group contour", objects, None))
    return out
