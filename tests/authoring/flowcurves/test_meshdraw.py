"""The bent mesh as rendered: the crystal tree's pixels are where the bend put them, not at rest.

Broken by drawing the rest mesh (``matrices[:, :3, 3] = 0`` in ``MeshDrawer.instance``): the
crystal's pixels stay at its rest place and the bent place shows sky.
"""

from __future__ import annotations

import numpy as np
import pytest

from engine.render.headless import egl_available

_reason = egl_available()
pytestmark = pytest.mark.skipif(_reason is not None, reason=f"no headless EGL OpenGL 3.3 context: {_reason}")


def _render(viewer, objects, rest) -> np.ndarray:  # type: ignore[no-untyped-def]
    from authoring.flowcurves.view import draw_objects
    from engine.render import RenderScene

    scene = RenderScene()
    scene.complete = True
    draw_objects(scene, objects, rest)
    viewer.draw(scene)
    return viewer.read_pixels().astype(np.int64)


def test_the_bent_crystal_is_drawn_where_the_bend_put_it() -> None:
    from engine.render import Viewer, make_target
    from puppetphone.bench.flow_mesh import bend

    scene, session = bend()
    viewer = Viewer(make_target(True, *scene.size, samples=0))
    try:
        viewer.camera = scene.camera
        empty = _render(viewer, [], [])
        bent = _render(viewer, session.objects, scene.objects)
        upright = _render(viewer, scene.objects, scene.objects)
    finally:
        viewer.close()
    gem = slice(12 * 8 + 8, 12 * 8 + 8 + 6)  # the octahedron's six vertices, after the trunk's 13 rings
    at_rest = np.rint(scene.camera.project(scene.objects[0].mesh.vertices[gem].mean(0)[None], *scene.size)[0])
    at_bent = np.rint(scene.camera.project(session.objects[0].mesh.vertices[gem].mean(0)[None], *scene.size)[0])
    assert np.linalg.norm(at_bent - at_rest) > 40.0

    def px(img: np.ndarray, xy: np.ndarray) -> np.ndarray:
        x, y = int(xy[0]), int(xy[1])
        return img[y - 1 : y + 2, x - 1 : x + 2].reshape(-1, img.shape[-1])[:, :3].mean(0)

    assert np.abs(px(bent, at_bent) - px(empty, at_bent)).max() > 30  # the crystal is drawn at its bent place
    assert np.abs(px(bent, at_rest) - px(empty, at_rest)).max() < 8  # and nothing is left where it stood
    assert np.abs(px(upright, at_rest) - px(empty, at_rest)).max() > 30  # (the unbent tree does cover it)
