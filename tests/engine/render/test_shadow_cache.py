"""The shadow map and ground mask are reused while the sun and every caster stand still.

Off by default (benches time a moving scene); the runner turns it on. Broken once to see it
fail: with the key check removed (``Shadows.render`` called every
frame) the first test counts two draws where one is expected.
"""

import numpy as np
import pytest

from engine.camera import OrbitCamera
from engine.render import RenderScene
from engine.render.headless import egl_available
from engine.render.quality import QUALITIES

_reason = egl_available()
pytestmark = pytest.mark.skipif(_reason is not None, reason=f"no headless EGL OpenGL 3.3 context: {_reason}")


def _scene(x: float) -> RenderScene:
    scene = RenderScene()
    scene.add_capsule([x, 0.3, 0.0], [x, 1.5, 0.0], 0.3, (0.8, 0.2, 0.2))
    scene.add_spheres([[1.0, 0.4, 0.5]], 0.4)
    return scene


@pytest.mark.parametrize("level", ["low", "high"])
def test_a_still_scene_draws_its_shadows_once_and_a_moved_caster_draws_them_again(monkeypatch, level):
    from engine.render import Viewer, make_target
    from engine.render.shadows import Shadows

    calls = []
    original = Shadows.render
    monkeypatch.setattr(Shadows, "render", lambda self, *a, **k: (calls.append(1), original(self, *a, **k))[1])
    viewer = Viewer(make_target(True, 320, 240, samples=0))
    try:
        with viewer.target.ctx:
            viewer.renderer.set_quality(QUALITIES[level])
        viewer.renderer.reuse_shadows = True  # as the runner sets it
        viewer.camera = OrbitCamera(target=np.array([0.0, 0.9, 0.0]), pitch=0.4, distance=5.0)
        still = _scene(0.0)
        viewer.draw(still)
        first = viewer.read_pixels().copy()
        viewer.draw(still)
        assert len(calls) == 1  # the second frame reused the map and the mask
        assert np.array_equal(viewer.read_pixels(), first)  # and shows the same shadows
        moved = _scene(-0.8)
        viewer.draw(moved)
        assert len(calls) == 2
        moved_image = viewer.read_pixels().copy()
    finally:
        viewer.close()
    fresh = Viewer(make_target(True, 320, 240, samples=0))
    try:
        with fresh.target.ctx:
            fresh.renderer.set_quality(QUALITIES[level])
        fresh.camera = OrbitCamera(target=np.array([0.0, 0.9, 0.0]), pitch=0.4, distance=5.0)
        fresh.draw(moved)
        assert np.array_equal(fresh.read_pixels(), moved_image)  # a redrawn map is the map a fresh frame draws
    finally:
        fresh.close()
