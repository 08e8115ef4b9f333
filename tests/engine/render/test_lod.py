"""Level of detail: each mesh level keeps the outline within a pixel, and is picked by size on screen."""

import math

import numpy as np
import pytest

from engine.camera import OrbitCamera
from engine.render import RenderScene
from engine.render.headless import egl_available
from engine.render.lod import CAPSULE_LEVELS, SILHOUETTE_ERROR_PX, SPHERE_LEVELS, choose_levels, level_limits

W, H = 320, 240


def rows(a, b, r):
    a, b = np.atleast_2d(a), np.atleast_2d(b)
    out = np.zeros((len(a), 11), dtype=np.float32)
    out[:, 0:3], out[:, 3:6], out[:, 6] = a, b, r
    return out


@pytest.mark.parametrize("levels", [CAPSULE_LEVELS, SPHERE_LEVELS])
def test_each_level_draws_up_to_the_radius_where_its_outline_is_a_pixel_off(levels):
    limits = level_limits(levels)
    assert len(limits) == len(levels) - 1 and np.all(np.diff(limits) > 0)
    for (segments, _), limit in zip(levels, limits):
        assert limit * (1.0 - math.cos(math.pi / segments)) == pytest.approx(SILHOUETTE_ERROR_PX)


def test_levels_follow_the_size_on_screen():
    limits = level_limits(SPHERE_LEVELS)
    eye = np.zeros(3)
    px_per_metre = 500.0
    far_small = rows([0, 0, -40], [0, 0, -40], 0.2)  # 2.5 px
    near_big = rows([0, 0, -3], [0, 0, -3], 1.0)  # 250 px
    assert choose_levels(far_small, eye, px_per_metre, limits)[0] == 0
    assert choose_levels(near_big, eye, px_per_metre, limits)[0] == len(SPHERE_LEVELS) - 1
    inside = rows([0, 0, 0.1], [0, 0, 0.1], 0.5)
    assert choose_levels(inside, eye, px_per_metre, limits)[0] == len(SPHERE_LEVELS) - 1
    # A long capsule pointing at the camera is sized by its near end, not its centre.
    limits = level_limits(CAPSULE_LEVELS)
    along = rows([0, 0, -4], [0, 0, -24], 0.2)
    across = rows([-10, 0, -14], [10, 0, -14], 0.2)
    assert choose_levels(along, eye, px_per_metre, limits)[0] > choose_levels(across, eye, px_per_metre, limits)[0]


@pytest.mark.skipif(egl_available() is not None, reason="no headless EGL OpenGL 3.3 context")
def test_a_sphere_drawn_at_each_level_keeps_its_true_outline():
    from engine.render import Viewer, make_target

    viewer = Viewer(make_target(True, W, H, samples=0))
    try:
        limits = level_limits(SPHERE_LEVELS)
        distance = 6.0
        viewer.camera = OrbitCamera(target=np.zeros(3), yaw=0.0, pitch=0.0, distance=distance, ground=None)
        f = H / (2.0 * math.tan(math.radians(viewer.camera.fov_y) / 2.0))
        empty = RenderScene()
        empty.ground.visible = False
        viewer.draw(empty)
        background = viewer.read_pixels().astype(int)
        yy, xx = np.mgrid[0:H, 0:W] + 0.5
        centre_px = np.array([W / 2.0, H / 2.0])
        for level, estimate_px in enumerate(np.r_[limits * 0.97, 110.0]):
            # The estimate is taken at the nearest point (distance - r): a little larger
            # than the true outline, a circle of f r / sqrt(d^2 - r^2) pixels.
            r = estimate_px * distance / (f + estimate_px)
            radius_px = f * r / math.sqrt(distance**2 - r**2)
            assert choose_levels(rows([0, 0, 0], [0, 0, 0], r), viewer.camera.eye, f, limits)[0] == level
            scene = RenderScene()
            scene.ground.visible = False
            scene.sun.shadows = False
            scene.add_sphere([0.0, 0.0, 0.0], r, color=(1.0, 0.0, 0.0))
            viewer.draw(scene)
            image = viewer.read_pixels().astype(int)
            drawn = np.abs(image - background).sum(axis=2) > 40
            off = np.hypot(xx - centre_px[0], yy - centre_px[1]) - radius_px
            assert drawn[off < -2.0].all(), f"level {level}: a hole inside the outline"
            assert not drawn[off > 1.0].any(), f"level {level}: drawn outside the outline"
    finally:
        viewer.close()
