"""Ray-cast impostors (quality ``low``): round outlines at any size, and their share of the shadow map.

Broken once to see each test fail: with ``Quality.impostors`` off at ``low`` the sphere is
the coarsest mesh (a 10-gon's area, 93.5 % of the disc) and the first test fails; with the
impostors' shadow-map draw removed (``Impostors.draw_depth`` returning at once) the ground
under the sphere stays lit and the second fails.
"""

import math

import numpy as np
import pytest

from engine.camera import OrbitCamera
from engine.render import RenderScene
from engine.render.headless import egl_available
from engine.render.impostors import box_corners
from engine.render.quality import QUALITIES

_reason = egl_available()
needs_gl = pytest.mark.skipif(_reason is not None, reason=f"no headless EGL OpenGL 3.3 context: {_reason}")


def test_the_box_is_closed_and_every_face_looks_outwards():
    corners, tris = box_corners()
    assert len(tris) == 12
    p = corners[tris]
    normals = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    centres = p.mean(axis=1)
    assert np.all(np.einsum("ij,ij->i", normals, centres) > 0)  # outward: counter-clockwise from outside
    edges = {tuple(sorted(e)) for t in tris for e in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0]))}
    assert len(edges) == 18  # 12 cube edges + 6 face diagonals: closed, each edge shared by two triangles


def _render(scene: RenderScene, camera: OrbitCamera, size: tuple[int, int] = (320, 240)) -> np.ndarray:
    from engine.render import Viewer, make_target

    viewer = Viewer(make_target(True, *size, samples=0))
    try:
        with viewer.target.ctx:
            viewer.renderer.set_quality(QUALITIES["low"])
        viewer.camera = camera
        viewer.draw(scene)
        return viewer.read_pixels().astype(np.int32)
    finally:
        viewer.close()


@needs_gl
def test_at_low_a_sphere_small_on_screen_is_a_true_disc_not_a_coarse_polygon():
    scene = RenderScene()
    scene.ground.visible = False
    scene.sun.shadows = False
    scene.sky_color = scene.horizon_color = (0.0, 0.0, 0.0)
    radius, distance = 0.5, 6.0
    scene.add_spheres([[0.0, 2.0, 0.0]], radius, color=(1.0, 0.2, 0.2))
    camera = OrbitCamera(target=np.array([0.0, 2.0, 0.0]), pitch=0.0, distance=distance)
    img = _render(scene, camera, (640, 480))
    red = img[..., 0] - img[..., 2]
    area = float(np.count_nonzero(red > 40))
    # The projected disc: its angular radius is asin(r / d); 480 px span the vertical field of view.
    px_per_tan = 240 / math.tan(math.radians(camera.fov_y) / 2.0)
    r_px = px_per_tan * math.tan(math.asin(radius / distance))
    assert area == pytest.approx(math.pi * r_px**2, rel=0.03)  # a 10-gon would be 6.5 % short


@needs_gl
def test_at_low_impostors_cast_their_shadow_on_the_ground():
    scene = RenderScene()
    scene.sun.direction = (0.0, 1.0, 0.0)  # straight overhead: the shadow lies right under the sphere
    scene.add_spheres([[0.0, 0.8, 0.0]], 0.4)
    camera = OrbitCamera(target=np.array([0.0, 0.4, 0.0]), pitch=0.9, distance=4.0, yaw=0.0)
    lit = RenderScene()
    lit.sun.direction = (0.0, 1.0, 0.0)
    lit.add_spheres([[0.0, 0.8, 0.0]], 0.4)
    lit.sun.shadows = False
    shadowed, bright = _render(scene, camera), _render(lit, camera)
    # Ground beside the sphere's outline, towards the camera-facing lower edge, where the shadow disc shows.
    diff = (bright - shadowed).sum(axis=2)
    assert np.count_nonzero(diff > 30) > 200
