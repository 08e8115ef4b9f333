"""The snowman field bent by Flow Curves: ``puppetphone play snowman --flow FILE``.

The field's static scenery — each pine tree's trunk, three tiers and three snow caps,
and the rocks — is described here once as plain data (:func:`scenery_objects`), for
the flow editor to deform; a flow file saved by ``puppetphone author flow snowman``
holds the same objects, deformed. :func:`prepare_flow` reads and checks that file
before the game is built (the objects go into the game's setup, so a recording's
header carries them and a replay needs no file); :func:`bent_scenery` turns them into
what the game uses: the trees' drawn primitives, and where the rocks and the trees'
obstacles stand (the puppets and the stick collide with the bent field). Moving things
— puppets, snowballs, snowmen — are not part of it and keep their shapes.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from authoring.flowcurves.scene import FlowScene
    from engine.camera import OrbitCamera

__all__ = [
    "scenery_objects",
    "prepare_flow",
    "recorded_flow",
    "BentScenery",
    "bent_scenery",
    "TRUNK_COLOR",
    "SNOW_COLOR",
]

TRUNK_COLOR = (0.36, 0.25, 0.17)
SNOW_COLOR = (0.95, 0.97, 1.0)
ROCK_COLOR = (0.48, 0.5, 0.54)
_TIERS = ((1.0, 1.0), (1.9, 0.75), (2.7, 0.5))


def _prim(a: Any, b: Any, r: float, color: tuple[float, float, float]) -> dict[str, Any]:
    return {"a": [float(v) for v in a], "b": [float(v) for v in b], "radius": float(r), "color": list(color)}


def scenery_objects() -> list[dict[str, Any]]:
    """Every static object of the field: ``{"name", "group", "primitives": [{"a", "b", "radius", "color"}]}``."""
    from games.snowman.scenery import ROCKS, TREES

    out = []
    for t, (x, z, s) in enumerate(TREES):
        base, group = np.array([x, 0.0, z]), f"tree{t}"
        out.append(
            {
                "name": f"{group}.trunk",
                "group": group,
                "primitives": [_prim(base, base + [0, 1.2 * s, 0], 0.12 * s, TRUNK_COLOR)],
            }
        )
        for k, (h, r) in enumerate(_TIERS):
            c = base + [0, h * s, 0]
            out.append(
                {
                    "name": f"{group}.tier{k}",
                    "group": group,
                    "primitives": [
                        _prim(c - [0, 0.05 * s, 0], c + [0, 0.35 * s, 0], r * s * 0.9, (0.16, 0.36 - 0.03 * k, 0.24))
                    ],
                }
            )
            cap = c + [0, 0.45 * s, 0]
            out.append(
                {"name": f"{group}.cap{k}", "group": group, "primitives": [_prim(cap, cap, 0.35 * r * s, SNOW_COLOR)]}
            )
    for k, (x, z, r) in enumerate(ROCKS):
        centre = [x, 0.6 * r, z]
        out.append({"name": f"rock{k}", "group": f"rock{k}", "primitives": [_prim(centre, centre, r, ROCK_COLOR)]})
    return out


def prepare_flow(path: str) -> list[dict[str, Any]] | None:
    """The deformed objects of a flow file for the snowman field (``GameOptionError`` if unusable)."""
    if not path:
        return None  # before the imports: the flow tools (and SciPy's optimiser) cost every plain start 0.3 s
    from authoring.flowcurves.storage import FlowFileError, load_flow
    from games.base import GameOptionError

    try:
        doc = load_flow(Path(path).expanduser())
    except FlowFileError as exc:
        raise GameOptionError(f"flow: {exc}") from None
    if doc["scene"] != "snowman":
        raise GameOptionError(f"flow: {path} bends the scene {doc['scene']!r}, not the snowman field")
    check_objects(doc["objects"])
    return doc["objects"]


def recorded_flow(value: Any) -> list[dict[str, Any]]:
    """The bent objects a recording's set-up carries, checked like a flow file's (``GameOptionError``)."""
    from authoring.flowcurves.storage import FlowFileError, parse_objects
    from games.base import GameOptionError

    try:
        objects = parse_objects(value)
    except FlowFileError as exc:
        raise GameOptionError(f"the recorded flow: {exc}") from None
    check_objects(objects)
    return objects


def check_objects(objects: list[dict[str, Any]]) -> None:
    """The flow objects must be this field's, part for part (a file from another version of the field is refused)."""
    from games.base import GameOptionError

    want = {o["name"]: (o["group"], len(o["primitives"])) for o in scenery_objects()}
    have = {o["name"]: (o["group"], len(o["primitives"])) for o in objects}
    if have != want:
        missing = (
            sorted(set(want) - set(have)) or sorted(set(have) - set(want)) or ["groups or primitive counts differ"]
        )
        raise GameOptionError(f"flow: the file's objects are not this field's ({', '.join(missing[:3])})")


@dataclass
class BentScenery:
    """What the bent field draws: the trees' capsules ``(a, b, r, colour)`` and spheres ``(centre, r)``.

    Display only (positions that matter to the simulation are the obstacles' entities).
    """

    SIM_STATE = False

    capsules: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]
    spheres: tuple[np.ndarray, np.ndarray]


def bent_scenery(objects: list[dict[str, Any]]) -> tuple[BentScenery, list[np.ndarray], list[np.ndarray]]:
    """The trees to draw, where each tree's trunk stands, where each rock's centre is."""
    caps, balls, trunks, rocks = [], [], [], []
    spheres = {o["name"] for o in scenery_objects() if all(p["a"] == p["b"] for p in o["primitives"])}
    for o in objects:
        for p in o["primitives"]:
            a, b = np.array(p["a"]), np.array(p["b"])
            if o["group"].startswith("rock"):
                rocks.append(a)
            elif o["name"] in spheres:  # what a part is comes from the field, not from where the file put its ends
                balls.append((a, p["radius"]))
            else:
                caps.append((a, b, p["radius"], p["color"]))
        if o["name"].endswith(".trunk"):
            trunks.append(np.array(o["primitives"][0]["a"]))
    a, b, r, col = (np.array(v) for v in zip(*caps))
    centre, radius = (np.array(v) for v in zip(*balls))
    return BentScenery((a, b, r, col), (centre, radius)), trunks, rocks


def flow_camera() -> OrbitCamera:
    """The camera the field is bent from: over the field from the south-east, every tree in view."""
    from engine.camera import OrbitCamera

    return OrbitCamera(target=np.array([0.0, 0.8, 0.0]), yaw=0.35, pitch=0.42, distance=17.0)


def flow_scene(size: tuple[int, int] = (1280, 720)) -> FlowScene:
    """The field's static scenery as a flow scene (6 trees × 7 parts + 3 rocks = 45 objects)."""
    from authoring.flowcurves.adapters import scene_from_data

    return scene_from_data("snowman", scenery_objects(), flow_camera(), size)
