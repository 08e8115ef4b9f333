"""A small flow scene shared by the deformation tests: one pine tree of the snowman field, planted."""

from __future__ import annotations

import numpy as np
import pytest

from authoring.flowcurves.adapters import objects_from_data
from authoring.flowcurves.scene import FlowScene
from engine.camera import OrbitCamera
from games.snowman.bent_scenery import scenery_objects


def tree_scene() -> FlowScene:
    """The field's first tree (trunk, three tiers, three snow caps) seen from its side."""
    objs = [o for o in objects_from_data(scenery_objects()) if o.group == "tree0"]
    cam = OrbitCamera(target=[-5.0, 1.5, -4.5], yaw=0.0, pitch=0.15, distance=8.0)
    return FlowScene("tree", objs, cam, (640, 480))


@pytest.fixture(scope="session")
def tree_securves():
    """The tree's automatic SEcurves (the CMA contour search runs once for all tests)."""
    from authoring.flowcurves.deform import SceneDeformer
    from authoring.flowcurves.securves import compute_securves

    scene = tree_scene()
    return compute_securves(scene, SceneDeformer(scene).rasters)


def bend_stroke(securve_points: np.ndarray, gap: float = 20.0) -> np.ndarray:
    """A stroke up the right side of a curve that leans to the right as it rises."""
    p = securve_points
    y = np.linspace(p[:, 1].max(), p[:, 1].min() - 20.0, 40)
    return np.c_[p[:, 0].max() + gap + 0.006 * (y.max() - y) ** 2, y]
