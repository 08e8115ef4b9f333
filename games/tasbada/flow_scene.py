"""Tasbada's virtual world as a flow scene: crystal trees and floating islands, for ``author flow tasbada``.

The virtual stage of the journey (:func:`games.tasbada.draw._virtual`) draws a forest of
crystal trees — a slender purple trunk with a crystal on top — and islands floating over
it. Bent by Flow Curves (thesis ch. 3) they must bend, not just move, so each is one
triangle mesh: a trunk is a tapered tube of many rings (so Eq. 3.9 has vertices all the
way up to bend it by), its crystal an octahedron resting on its tip; an island is a slab of
grass over an upturned cone of rock. Trees stand on the ground (their foot stays where it
is, §3.5.3); islands touch nothing, so a stroke carries them along whole (the thesis' birds).

Described as plain data (:func:`flow_objects`), like the snowman field's scenery, so the
flow editor never imports the game. Laid out by a seeded generator: the same every run.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from authoring.flowcurves.scene import FlowScene
    from engine.camera import OrbitCamera

__all__ = ["SCENE", "crystal_tree", "flow_camera", "flow_objects", "island"]

from engine.arrays import F64 as F

SCENE = "tasbada"
TRUNK_COLOR = (0.45, 0.35, 0.6)
CRYSTAL_COLORS = ((0.5, 0.95, 0.9), (1.0, 0.6, 0.85))
GRASS_COLOR = (0.35, 0.7, 0.5)
ROCK_COLOR = (0.5, 0.42, 0.6)


def _tube(base: F, height: float, r0: float, r1: float, rings: int, sides: int) -> tuple[F, list[list[int]]]:
    """A tapered open tube along +y: ``rings + 1`` rings of ``sides`` vertices, and its quads as triangles."""
    ang = 2.0 * np.pi * np.arange(sides) / sides
    verts, faces = [], []
    for k in range(rings + 1):
        t = k / rings
        r = r0 + (r1 - r0) * t
        verts.extend(base + np.c_[r * np.cos(ang), np.full(sides, t * height), r * np.sin(ang)])
    for k in range(rings):
        for s in range(sides):
            a, b = k * sides + s, k * sides + (s + 1) % sides
            faces += [[a, b + sides, b], [a, a + sides, b + sides]]
    return np.array(verts), faces


def _octahedron(centre: F, half: float, turn: float) -> tuple[F, list[list[int]]]:
    c, s = math.cos(turn), math.sin(turn)
    ring = [
        np.array([c * half, 0.0, s * half]),
        np.array([-s * half, 0.0, c * half]),
        np.array([-c * half, 0.0, -s * half]),
        np.array([s * half, 0.0, -c * half]),
    ]
    verts = [centre + [0.0, 1.3 * half, 0.0], centre - [0.0, 1.3 * half, 0.0]] + [centre + r for r in ring]
    faces = []
    for k in range(4):
        a, b = 2 + k, 2 + (k + 1) % 4
        faces += [[0, a, b], [1, b, a]]
    return np.array(verts), faces


def crystal_tree(base: Any, height: float, turn: float = 0.0, crystal: int = 0) -> dict[str, Any]:
    """One crystal tree's mesh as plain data: a trunk of 12 rings (apex cap included) and its crystal."""
    base = np.asarray(base, dtype=np.float64)
    trunk, tf = _tube(base, height, 0.09, 0.05, 12, 8)
    gem, gf = _octahedron(base + [0.0, height + 0.22, 0.0], 0.24, turn)
    n = len(trunk)
    tip = n + len(gem)  # a centre vertex closing the trunk's top
    verts = np.vstack([trunk, gem, base + [0.0, height, 0.0]])
    top = 12 * 8
    faces = tf + [[f + n for f in tri] for tri in gf] + [[top + s, tip, top + (s + 1) % 8] for s in range(8)]
    colors = [list(TRUNK_COLOR)] * len(tf) + [list(CRYSTAL_COLORS[crystal % 2])] * len(gf) + [list(TRUNK_COLOR)] * 8
    return {"vertices": np.round(verts, 6).tolist(), "faces": faces, "color": list(TRUNK_COLOR), "face_colors": colors}


def island(centre: Any, size: float) -> dict[str, Any]:
    """A floating island's mesh as plain data: a grass slab (a flat 8-sided prism) over a cone of rock."""
    centre = np.asarray(centre, dtype=np.float64)
    slab, sf = _tube(centre - [0.0, 0.12 * size, 0.0], 0.24 * size, 0.9 * size, 0.9 * size, 2, 8)
    n = len(slab)
    ang = 2.0 * np.pi * np.arange(8) / 8
    rock = np.vstack(
        [
            centre + np.c_[0.85 * size * np.cos(ang), np.full(8, -0.12 * size), 0.85 * size * np.sin(ang)],
            centre + [0.0, -0.9 * size, 0.0],
            centre + [0.0, 0.12 * size, 0.0],
        ]
    )
    rf = [[n + s, n + (s + 1) % 8, n + 8] for s in range(8)]
    top = [[16 + s, n + 9, 16 + (s + 1) % 8] for s in range(8)]
    verts = np.vstack([slab, rock])
    faces = sf + rf + top
    colors = [list(GRASS_COLOR)] * (len(sf) + len(top))
    colors[len(sf) :] = [list(ROCK_COLOR)] * len(rf) + [list(GRASS_COLOR)] * len(top)
    return {"vertices": np.round(verts, 6).tolist(), "faces": faces, "color": list(GRASS_COLOR), "face_colors": colors}


def flow_objects() -> list[dict[str, Any]]:
    """Seven crystal trees on the ground and three islands floating over them, as flow objects' data."""
    rng = np.random.default_rng(7)
    out = []
    for k in range(7):
        x = -3.6 + 1.2 * k + rng.uniform(-0.25, 0.25)
        z = -1.0 - rng.uniform(0.0, 2.0)
        out.append(
            {
                "name": f"tree{k}",
                "group": f"tree{k}",
                "primitives": [],
                "mesh": crystal_tree([x, 0.0, z], 1.6 + 0.6 * rng.uniform(), rng.uniform(0, np.pi), k),
            }
        )
    for k in range(3):
        c = [-3.0 + 3.0 * k + rng.uniform(-0.4, 0.4), 3.3 + 0.5 * rng.uniform(), -4.0 - rng.uniform(0.0, 1.5)]
        out.append({"name": f"island{k}", "group": f"island{k}", "primitives": [], "mesh": island(c, 0.8)})
    return out


def flow_camera() -> OrbitCamera:
    """The view the forest is bent from: level with the islands' undersides, the whole forest in frame."""
    from engine.camera import OrbitCamera

    return OrbitCamera(target=np.array([0.0, 1.9, -2.0]), yaw=0.0, pitch=0.05, distance=8.5)


def flow_scene(size: tuple[int, int] = (1280, 720)) -> FlowScene:
    """The forest as a :class:`~authoring.flowcurves.scene.FlowScene` (the editor's and the bench's)."""
    from authoring.flowcurves.adapters import scene_from_data

    return scene_from_data(SCENE, flow_objects(), flow_camera(), size)
