"""The scenery's shadow depth (cones, boxes) is drawn once and copied under the moving casters each frame.

Each frame is compared with a fresh renderer's frame of the same scene drawn without the copy
(the depth blit made to fail, so every caster is drawn into the cleared map, as before the
cache): the copy must give the same pixels, and a moved tree must be drawn again.
"""

import numpy as np
import pytest

from engine.camera import OrbitCamera
from engine.render import RenderScene
from engine.render.headless import egl_available
from engine.render.quality import QUALITIES
from tests.engine.render.drawn import drawn

_reason = egl_available()
pytestmark = pytest.mark.skipif(_reason is not None, reason=f"no headless EGL OpenGL 3.3 context: {_reason}")

_CAMERA = OrbitCamera(target=np.array([0.0, 0.6, 0.0]), pitch=0.6, distance=6.0)


def _scene(puppet_x: float, tree_x: float = -2.0) -> RenderScene:
    """Two trees and a rock spanning the casters' box, and a capsule (the puppet) moving inside it."""
    scene = RenderScene()
    scene.add_cones([[tree_x, 0.0, -1.0], [2.0, 0.0, -1.5]], [[tree_x, 3.0, -1.0], [2.0, 3.0, -1.5]], [0.6, 0.6])
    scene.add_box([1.5, 0.25, 1.5], [0.3, 0.25, 0.3])
    scene.add_capsule([puppet_x, 0.3, 0.3], [puppet_x, 1.5, 0.3], 0.25, (0.8, 0.2, 0.2))
    return scene


def _fresh(scene: RenderScene, level: str) -> np.ndarray:
    """``scene`` drawn by a new renderer that cannot copy depth (the fallback: scenery drawn into the map)."""
    import engine.render.shadows as shadows

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(shadows, "blit_depth", lambda *a: False)
        return drawn(scene, _CAMERA, level)


@pytest.mark.parametrize("level", ["low", "high"])
def test_the_scenery_is_drawn_once_while_the_puppet_moves_and_again_when_a_tree_moves(monkeypatch, level):
    """Broken once by not copying the kept depth (the map starts cleared): the trees' shadows vanish
    from the second frame on and the comparison fails; and once by never drawing the scenery again
    (the key check removed): the scenery is drawn once where twice is expected.
    """
    from engine.render import Viewer, make_target
    from engine.render.shadows import Shadows

    draws = []
    original = Shadows._draw_scenery
    monkeypatch.setattr(Shadows, "_draw_scenery", lambda self, cones: (draws.append(1), original(self, cones))[1])
    scenes = [_scene(-0.6), _scene(0.1), _scene(0.7), _scene(0.7, tree_x=-1.2)]
    viewer = Viewer(make_target(True, 320, 240, samples=0))
    images = []
    try:
        with viewer.target.ctx:
            viewer.renderer.set_quality(QUALITIES[level])
        viewer.camera = _CAMERA
        counts = []
        for scene in scenes:
            viewer.draw(scene)
            images.append(viewer.read_pixels().copy())
            counts.append(len(draws))
    finally:
        viewer.close()
    assert counts == [1, 1, 1, 2]  # the puppet's moves reuse the scenery; the moved tree redraws it
    draws.clear()
    for scene, image in zip(scenes, images, strict=True):
        assert np.array_equal(image, _fresh(scene, level))
