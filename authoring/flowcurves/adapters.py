"""Scenes to open in the flow editor: the snowman field's static scenery.

The snowman field draws each pine tree as a trunk, three snowy tiers and three snow
caps (``games.snowman.scenery``): seven objects that touch, so a tree bends as one
while its parts stay attached — 6 trees × 7 + 3 rocks = 45 objects. Moving things
(puppets, snowballs, snowmen) are not part of it: they keep their own shapes.
"""

from __future__ import annotations

import numpy as np

from authoring.flowcurves.scene import FlowObject, FlowScene, Primitive

__all__ = ["snowman_scene", "SCENES", "open_scene"]

_TRUNK = (0.36, 0.25, 0.17)
_SNOW = (0.95, 0.97, 1.0)


def snowman_objects() -> list[FlowObject]:
    """The field's trees (seven parts each) and rocks, built as ``games.snowman.scenery`` draws them."""
    from games.snowman.scenery import ROCKS, TREES

    objects = []
    for t, (x, z, s) in enumerate(TREES):
        base = np.array([x, 0.0, z])
        group = f"tree{t}"
        objects.append(FlowObject(f"{group}.trunk", group, [Primitive(base, base + [0, 1.2 * s, 0], 0.12 * s, _TRUNK)]))
        for k, (h, r) in enumerate(((1.0, 1.0), (1.9, 0.75), (2.7, 0.5))):
            c = base + [0, h * s, 0]
            color = (0.16, 0.36 - 0.03 * k, 0.24)
            objects.append(FlowObject(f"{group}.tier{k}", group,
                                      [Primitive(c - [0, 0.05 * s, 0], c + [0, 0.35 * s, 0], r * s * 0.9, color)]))
            cap = c + [0, 0.45 * s, 0]
            objects.append(FlowObject(f"{group}.cap{k}", group, [Primitive(cap, cap.copy(), 0.35 * r * s, _SNOW)]))
    for k, (x, z, r) in enumerate(ROCKS):
        centre = np.array([x, 0.6 * r, z])
        objects.append(FlowObject(f"rock{k}", f"rock{k}", [Primitive(centre, centre.copy(), r, (0.48, 0.5, 0.54))]))
    return objects


def snowman_scene(size: tuple[int, int] = (1280, 720)) -> FlowScene:
    """The snowman field from a camera that frames all its trees."""
    from engine.camera import OrbitCamera

    camera = OrbitCamera(target=[0.0, 0.8, 0.0], yaw=0.35, pitch=0.42, distance=17.0)
    return FlowScene("snowman", snowman_objects(), camera, tuple(size))  # type: ignore[arg-type]


SCENES = {"snowman": snowman_scene}


def open_scene(name: str, size: tuple[int, int] = (1280, 720)) -> FlowScene:
    """A named scene; ``ValueError`` names the ones there are."""
    if name not in SCENES:
        raise ValueError(f"no flow scene {name!r} (scenes: {', '.join(SCENES)})")
    return SCENES[name](size)
