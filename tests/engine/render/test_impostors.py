"""Ray-cast impostors (quality ``low``): round outlines at any size, and their share of the shadow map.

Broken once to see each test fail: with ``Quality.impostors`` off at ``low`` the sphere is
the coarsest mesh (a 10-gon's area, 93.5 % of the disc) and the disc test fails; with the
impostors' shadow-map draw removed (``Impostors.draw_depth`` returning at once) the ground
under the sphere stays lit and the shadow test fails. With the quad through the capsule's
centre instead of in front of it (``centre`` = ``c`` in ``IMPOSTOR_VS``) the near end of a
capsule seen end-on is cut to a square and the end-on test fails; without the whole-view
quad near the eye (``near`` always false) a capsule reaching past the camera loses the part
beyond the near plane and the close-up test fails.
"""

import math

import numpy as np
import pytest

from engine.camera import OrbitCamera
from engine.render import RenderScene
from engine.render.headless import egl_available
from engine.render.impostors import quad_corners
from tests.engine.render.drawn import drawn

_reason = egl_available()
needs_gl = pytest.mark.skipif(_reason is not None, reason=f"no headless EGL OpenGL 3.3 context: {_reason}")


def test_the_quad_is_two_triangles_over_the_unit_square():
    corners, tris = quad_corners()
    assert corners.shape == (4, 2) and set(map(tuple, corners)) == {(-1, -1), (1, -1), (-1, 1), (1, 1)}
    p = corners[tris]
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    area = 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    assert area.sum() == pytest.approx(4.0)  # the two triangles tile the square


def _render(
    scene: RenderScene, camera: OrbitCamera, size: tuple[int, int] = (320, 240), quality: str = "low"
) -> np.ndarray:
    return drawn(scene, camera, quality, size)


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


def _red_mask(img: np.ndarray) -> np.ndarray:
    return (img[..., 0] - img[..., 2]) > 40


def _dark_scene() -> RenderScene:
    scene = RenderScene()
    scene.ground.visible = False
    scene.sun.shadows = False
    scene.sky_color = scene.horizon_color = (0.0, 0.0, 0.0)
    return scene


@needs_gl
def test_at_low_a_capsule_seen_end_on_shows_its_near_end_as_a_full_disc():
    scene = _dark_scene()
    radius, distance = 0.4, 5.0
    # The axis points at the eye: the near end sphere (at distance - 0.6) hides the rest.
    scene.add_capsules(np.array([[0.0, 2.0, -0.6]]), np.array([[0.0, 2.0, 0.6]]), radius, color=(1.0, 0.2, 0.2))
    camera = OrbitCamera(target=np.array([0.0, 2.0, 0.0]), pitch=0.0, yaw=0.0, distance=distance)
    img = _render(scene, camera, (640, 480))
    area = float(np.count_nonzero(_red_mask(img)))
    near = distance - 0.6
    px_per_tan = 240 / math.tan(math.radians(camera.fov_y) / 2.0)
    r_px = px_per_tan * math.tan(math.asin(radius / near))
    assert area == pytest.approx(math.pi * r_px**2, rel=0.03)


@needs_gl
def test_at_low_a_capsule_reaching_past_the_camera_is_drawn_as_the_mesh_draws_it():
    scene = _dark_scene()
    # A long bar beside the eye, from far ahead to behind the camera (it crosses the near plane).
    scene.add_capsules(np.array([[0.35, 1.8, -8.0]]), np.array([[0.35, 1.8, 8.0]]), 0.15, color=(1.0, 0.2, 0.2))
    camera = OrbitCamera(target=np.array([0.0, 2.0, 0.0]), pitch=0.0, yaw=0.0, distance=3.0)
    impostor = _red_mask(_render(scene, camera, quality="low"))
    mesh = _red_mask(_render(scene, camera, quality="high"))
    assert mesh.sum() > 2000  # the bar crosses much of the view
    overlap = np.count_nonzero(impostor & mesh) / np.count_nonzero(impostor | mesh)
    assert overlap > 0.95
