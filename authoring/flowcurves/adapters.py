"""Flow scenes from plain data: the objects a game describes, seen from a camera.

A game that wants its static scenery bent describes it as plain dicts (``{"name",
"group", "primitives": [{"a", "b", "radius", "color"}]}``, the same shape a flow file
stores), so authoring never imports a game: the launcher hands the data over.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from authoring.flowcurves.scene import FlowObject, FlowScene, Primitive
from engine.camera import Camera

__all__ = ["objects_from_data", "scene_from_data"]


def objects_from_data(objects: list[dict[str, Any]]) -> list[FlowObject]:
    """Flow objects from their plain description."""
    return [FlowObject(str(o["name"]), str(o["group"]),
                       [Primitive(np.array(p["a"], dtype=np.float64), np.array(p["b"], dtype=np.float64),
                                  float(p["radius"]), tuple(float(c) for c in p["color"]))  # type: ignore[arg-type]
                        for p in o["primitives"]]) for o in objects]


def scene_from_data(name: str, objects: list[dict[str, Any]], camera: Camera, size: tuple[int, int]) -> FlowScene:
    """A flow scene of the described objects."""
    return FlowScene(name, objects_from_data(objects), camera, (int(size[0]), int(size[1])))
