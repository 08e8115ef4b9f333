"""Where objects touch: the layout the deformation keeps (§3.5.3).

Two kinds of contact, found in 3D from the primitives and carried to the screen:

- **ground**: a primitive that reaches y ≤ 0 rests on the ground, which never deforms;
  its footprint's two screen-side extremes become fixed points (two, so a tree stays
  planted in place *and* upright at its base); a mesh's vertices at the ground
  (y ≤ :data:`GROUND_TOLERANCE`) are all fixed where they are seen (up to
  :data:`MESH_FEET`, spread across its foot), so a bent mesh keeps its whole foot;
- **touch**: primitives of two objects that overlap (a tier on its trunk, a snow cap on
  its tier, a snowman's stacked balls); the middle of the overlap and a point either side
  of it on screen must stay one point for both objects.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from authoring.flowcurves.scene import FlowScene, Primitive

__all__ = ["Contact", "find_contacts", "mesh_feet", "GROUND_TOLERANCE", "MESH_FEET"]

from engine.arrays import F64 as F

GROUND_TOLERANCE = 0.02
#: At most this many of a mesh's ground vertices become fixed points (spread evenly along screen x).
MESH_FEET = 12


@dataclass
class Contact:
    """Screen points ``[2, 2]`` shared by objects ``a`` and ``b`` (``b`` None: the ground)."""

    a: int
    b: int | None
    points: F


def _closest_between(p: Primitive, q: Primitive) -> tuple[F, F]:
    """Closest points of two segments (a sphere is a segment of length zero)."""
    d1, d2, r = p.b - p.a, q.b - q.a, p.a - q.a
    a, e, f = d1 @ d1, d2 @ d2, d2 @ r
    if a < 1e-12 and e < 1e-12:
        return p.a.copy(), q.a.copy()
    if a < 1e-12:
        return p.a.copy(), q.a + np.clip(f / e, 0, 1) * d2
    c = d1 @ r
    if e < 1e-12:
        return p.a + np.clip(-c / a, 0, 1) * d1, q.a.copy()
    b = d1 @ d2
    den = a * e - b * b
    s = np.clip((b * f - c * e) / den, 0, 1) if den > 1e-12 else 0.0
    t: F | float = (b * s + f) / e
    if t < 0:
        t, s = 0.0, np.clip(-c / a, 0, 1)
    elif t > 1:
        t, s = 1.0, np.clip((b - c) / a, 0, 1)
    return p.a + s * d1, q.a + t * d2


def _pair(scene: FlowScene, centre: F, across: F, half: float) -> F:
    """Two screen points ``half`` pixels either side of ``centre`` (3D) along screen direction ``across``."""
    w, h = scene.size
    xy = scene.camera.project(centre[None], w, h)[0]
    return np.array([xy - half * across, xy + half * across])


def _pixels_per_metre(scene: FlowScene, point: F) -> float:
    focal = scene.size[1] / (2.0 * np.tan(np.radians(scene.camera.fov_y) / 2.0))
    return float(focal / max(np.linalg.norm(point - scene.camera.eye), 1e-6))


def mesh_feet(scene: FlowScene, index: int) -> F:
    """Screen points ``[K, 2]`` of an object's mesh vertices at the ground (none: ``[0, 2]``)."""
    mesh = scene.objects[index].mesh
    if mesh is None:
        return np.zeros((0, 2))
    low = mesh.vertices[mesh.vertices[:, 1] <= GROUND_TOLERANCE]
    if not len(low):
        return np.zeros((0, 2))
    xy = np.unique(np.round(scene.camera.project(low, scene.size[0], scene.size[1]), 6), axis=0)
    xy = xy[np.argsort(xy[:, 0], kind="stable")]
    return xy[np.unique(np.linspace(0, len(xy) - 1, min(MESH_FEET, len(xy))).round().astype(np.int64))]


def find_contacts(scene: FlowScene) -> list[Contact]:
    """Every ground contact and every touching pair of objects, in object order (repeatable)."""
    out: list[Contact] = []
    right = np.array([1.0, 0.0])
    for i, obj in enumerate(scene.objects):
        if not scene.ground:
            break
        on_ground = mesh_feet(scene, i)
        if len(on_ground) >= 2:
            out.append(Contact(i, None, on_ground))
            continue
        feet = []
        for p in obj.primitives:
            low = p.a if p.a[1] <= p.b[1] else p.b
            depth = p.radius - low[1]  # how far the primitive reaches below y = 0
            if depth >= -GROUND_TOLERANCE:
                feet.append((depth, low * [1, 0, 1], np.sqrt(max(p.radius**2 - low[1] ** 2, (0.3 * p.radius) ** 2))))
        if feet:
            _, foot, radius = max(feet, key=lambda f: f[0])
            half = max(radius * _pixels_per_metre(scene, foot) * 0.8, 2.0)
            out.append(Contact(i, None, _pair(scene, foot, right, half)))
    for i, oa in enumerate(scene.objects):
        for j in range(i + 1, len(scene.objects)):
            best = None
            for p in oa.primitives:
                for q in scene.objects[j].primitives:
                    x, y = _closest_between(p, q)
                    gap = float(np.linalg.norm(x - y)) - p.radius - q.radius
                    if gap < 0 and (best is None or gap < best[0]):
                        best = (gap, x, y, p, q)
            if best is None:
                continue
            gap, x, y, p, q = best
            d = float(np.linalg.norm(y - x))
            centre = x + (y - x) * (p.radius + 0.5 * gap) / d if d > 1e-9 else 0.5 * (x + y)
            w, h = scene.size
            sx = scene.camera.project(np.array([x, y]), w, h)
            v = sx[1] - sx[0]
            across = right if np.linalg.norm(v) < 1.0 else np.array([-v[1], v[0]]) / np.linalg.norm(v)
            half = max(0.5 * min(p.radius, q.radius) * _pixels_per_metre(scene, centre), 2.0)
            out.append(Contact(i, j, _pair(scene, centre, across, half)))
    return out
