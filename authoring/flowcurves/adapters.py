"""Flow scenes from plain data: the objects a game describes, seen from a camera.

A game that wants its static scenery bent describes it as plain dicts (``{"name",
"group", "primitives": [{"a", "b", "radius", "color"}], "mesh": {"vertices", "faces",
"color", "face_colors"}}`` — the mesh optional, the same shape a flow file stores), so
authoring never imports a game: the launcher hands the data over.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

import numpy as np

from authoring.flowcurves.mesh import TriMesh
from authoring.flowcurves.scene import FlowObject, FlowScene, Primitive
from engine.camera import Camera

__all__ = ["objects_from_data", "scene_from_data", "mesh_from_data", "mesh_data"]


def _rgb(color: Iterable[float]) -> tuple[float, float, float]:
    """A colour's three channels as floats (the flow file's parser and the games' scenes give three)."""
    r, g, b = (float(c) for c in color)
    return r, g, b


def mesh_from_data(m: dict[str, Any]) -> TriMesh:
    """A triangle mesh from its plain description."""
    colors = m.get("face_colors")
    return TriMesh(
        np.array(m["vertices"], dtype=np.float64),
        np.array(m["faces"], dtype=np.int64),
        _rgb(m.get("color", (0.6, 0.6, 0.6))),
        None if colors is None else np.array(colors, dtype=np.float64),
    )


def mesh_data(mesh: TriMesh) -> dict[str, Any]:
    """The plain description of a mesh (vertices rounded to a micrometre, as flow files keep them)."""
    out: dict[str, Any] = {
        "vertices": np.round(mesh.vertices, 6).tolist(),
        "faces": mesh.faces.tolist(),
        "color": [float(c) for c in mesh.color],
    }
    if mesh.face_colors is not None:
        out["face_colors"] = mesh.face_colors.tolist()
    return out


def objects_from_data(objects: list[dict[str, Any]]) -> list[FlowObject]:
    """Flow objects from their plain description."""
    return [
        FlowObject(
            str(o["name"]),
            str(o["group"]),
            [
                Primitive(
                    np.array(p["a"], dtype=np.float64),
                    np.array(p["b"], dtype=np.float64),
                    float(p["radius"]),
                    _rgb(p["color"]),
                )
                for p in o.get("primitives", [])
            ],
            mesh_from_data(o["mesh"]) if o.get("mesh") is not None else None,
        )
        for o in objects
    ]


def scene_from_data(name: str, objects: list[dict[str, Any]], camera: Camera, size: tuple[int, int]) -> FlowScene:
    """A flow scene of the described objects."""
    return FlowScene(name, objects_from_data(objects), camera, (int(size[0]), int(size[1])))
