"""The camera pass skips capsules and spheres outside the view; the picture does not change.

Broken once to see it fail: with ``_in_view`` returning every row, the lit pass drew all 201
solids and the first assertion failed.
"""

import numpy as np
import pytest

from engine.camera import OrbitCamera
from engine.render import RenderScene
from engine.render.headless import egl_available
from engine.render.quality import QUALITIES

_reason = egl_available()
pytestmark = pytest.mark.skipif(_reason is not None, reason=f"no headless EGL OpenGL 3.3 context: {_reason}")


def _scene() -> RenderScene:
    scene = RenderScene()
    scene.add_capsule([0.0, 0.3, 0.0], [0.0, 1.5, 0.0], 0.3, (0.8, 0.2, 0.2))
    scene.add_capsule([-6.0, 0.5, 0.0], [-1.0, 0.5, 0.0], 0.2, (0.2, 0.3, 0.8))  # across the left edge
    rng = np.random.default_rng(2)
    behind = np.c_[rng.uniform(-20, 20, 199), rng.uniform(0.3, 2.0, 199), rng.uniform(12, 30, 199)]
    scene.add_spheres(behind, 0.3)  # behind the camera, which looks towards -z from z = 5
    return scene


@pytest.mark.parametrize("level", ["low", "high"])
def test_only_the_solids_in_view_are_drawn_and_the_picture_is_the_same(monkeypatch, level):
    import engine.render.renderer as R
    from engine.render import Viewer, make_target
    from engine.render.impostors import Impostors

    drawn = []
    lit = Impostors.draw
    monkeypatch.setattr(Impostors, "draw", lambda self, rows, eye: (drawn.append(len(rows)), lit(self, rows, eye))[1])
    uploads = []
    upload = R.LodBatches.upload
    monkeypatch.setattr(
        R.LodBatches, "upload", lambda self, rows, lv: (uploads.append(len(rows)), upload(self, rows, lv))[1]
    )
    images = []
    for cull in (True, False):
        if not cull:
            monkeypatch.setattr(R, "_in_view", lambda rows, vp: np.arange(len(rows)))
        drawn.clear()
        uploads.clear()
        viewer = Viewer(make_target(True, 320, 240, samples=0))
        try:
            with viewer.target.ctx:
                viewer.renderer.set_quality(QUALITIES[level])
            viewer.camera = OrbitCamera(target=np.array([0.0, 0.9, 0.0]), pitch=0.2, distance=5.0)
            viewer.draw(_scene())
            images.append(viewer.read_pixels())
        finally:
            viewer.close()
        shown = sum(drawn) + sum(uploads[:2])  # the camera pass: impostors, or the two kinds' LOD batches
        assert shown == (2 if cull else 201)
    assert np.array_equal(images[0], images[1])
