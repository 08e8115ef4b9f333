"""Overlays: a picture at a depth is hidden by nearer 3-D things and hides farther ones; one without
depth covers everything; both line up with the background photo."""

import numpy as np
import pytest

from engine.camera import OrbitCamera
from engine.render import RenderScene
from engine.render.headless import egl_available

W, H = 320, 180

_reason = egl_available()
pytestmark = pytest.mark.skipif(_reason is not None, reason=f"no headless EGL OpenGL 3.3 context: {_reason}")

CAM = OrbitCamera(target=np.array([0.0, 0.7, 0.0]), yaw=0.0, pitch=0.0, distance=6.0, fov_y=50.0)
GREEN = np.array([30, 200, 40], dtype=np.uint8)


@pytest.fixture(scope="module")
def gl():
    from engine.render import Viewer, make_target

    viewer = Viewer(make_target(True, W, H, samples=0))
    viewer.camera = CAM
    yield viewer
    viewer.close()


def _scene(box_z: float, depth_at: tuple[float, float, float] | None) -> RenderScene:
    s = RenderScene()
    s.sun.shadows = False
    s.set_background(np.full((90, 160, 3), 128, dtype=np.uint8), 0.0)
    pic = np.zeros((20, 20, 4), dtype=np.uint8)
    pic[..., :3], pic[..., 3] = GREEN, 255
    s.add_overlay(pic, (0.4, 0.3, 0.6, 0.7), depth_at=depth_at)  # the middle of the view
    s.add_box((0.0, 0.7, box_z), (0.3, 0.3, 0.3), color=(0.9, 0.1, 0.8))
    return s


def _centre(gl, scene) -> np.ndarray:
    gl.draw(scene)
    return gl.read_pixels().astype(int)[H // 2, W // 2]


def test_a_placed_overlay_is_behind_nearer_things_and_in_front_of_farther_ones(gl) -> None:
    at = (0.0, 0.0, 0.0)
    near = _centre(gl, _scene(2.0, at))  # the box is nearer the camera than the picture
    far = _centre(gl, _scene(-2.0, at))  # the box is behind it
    assert near[1] < 120 and near[0] > 120  # magenta box
    assert abs(far[1] - GREEN[1]) < 30 and far[0] < 80  # the picture's green


def test_an_overlay_without_depth_covers_even_the_nearest_thing(gl) -> None:
    top = _centre(gl, _scene(4.0, None))
    assert abs(top[1] - GREEN[1]) < 30 and top[0] < 80


def test_overlay_rect_lines_up_with_the_photo_and_bad_pictures_are_refused(gl) -> None:
    s = _scene(-50.0, None)
    gl.draw(s)
    img = gl.read_pixels().astype(int)
    assert img[H // 2, int(W * 0.45), 1] > 150 and img[H // 2, int(W * 0.3), 1] < 150  # inside / outside u 0.4..0.6
    with pytest.raises(ValueError, match="uint8"):
        s.add_overlay(np.zeros((4, 4, 3), dtype=np.uint8))
    with pytest.raises(ValueError, match="rect"):
        s.add_overlay(np.zeros((4, 4, 4), dtype=np.uint8), (0.5, 0.5, 0.2, 0.9))
