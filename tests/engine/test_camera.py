"""Cameras: matrices against pyglm, pixel rays and projection as exact inverses, orbit limits."""

import math

import numpy as np
import pytest
from pyglm import glm

from engine import quat
from engine.camera import OrbitCamera, PhoneCamera, look_at, perspective


def glm_to_np(m) -> np.ndarray:
    # pyglm indexes m[column][row]
    return np.array([[m[c][r] for c in range(4)] for r in range(4)])


@pytest.mark.parametrize("yaw,pitch,dist", [(0.0, 0.3, 5.0), (2.1, -0.1, 3.0), (-2.9, 1.2, 12.0)])
def test_orbit_view_matches_glm_lookat(yaw, pitch, dist):
    cam = OrbitCamera(target=np.array([0.5, 1.0, -2.0]), yaw=yaw, pitch=pitch, distance=dist)
    ref = glm.lookAt(glm.vec3(*cam.eye), glm.vec3(*cam.target), glm.vec3(0, 1, 0))
    assert np.allclose(cam.view_matrix(), glm_to_np(ref), atol=1e-6)
    assert np.allclose(look_at(cam.eye, cam.target), glm_to_np(ref), atol=1e-6)
    assert np.isclose(np.linalg.norm(cam.eye - cam.target), dist)


def test_projection_matches_glm_perspective():
    cam = OrbitCamera(fov_y=55.0, near=0.1, far=80.0)
    ref = glm.perspective(math.radians(55.0), 16 / 9, 0.1, 80.0)
    assert np.allclose(cam.projection(16 / 9), glm_to_np(ref), atol=1e-6)
    with pytest.raises(ValueError):
        perspective(50.0, 1.0, 1.0, 0.5)


def test_yaw_zero_looks_down_minus_z_at_the_target():
    cam = OrbitCamera(target=np.zeros(3), yaw=0.0, pitch=0.0, distance=4.0, ground=None)
    assert np.allclose(cam.eye, [0, 0, 4])
    assert np.allclose(cam.forward, [0, 0, -1])
    assert np.allclose(cam.right, [1, 0, 0])


@pytest.mark.parametrize(
    "make",
    [
        lambda: OrbitCamera(target=np.array([0.2, 0.9, 0.1]), yaw=0.7, pitch=0.4, distance=6.0),
        lambda: PhoneCamera(position=np.array([1.0, 1.6, 3.0]), orientation=quat.from_euler("YXZ", [0.3, -0.2, 0.1])),
    ],
)
def test_project_and_ray_are_inverse(make):
    cam = make()
    w, h = 640, 360
    rng = np.random.default_rng(0)
    # points in front of the camera
    pts = cam.eye + cam.forward * rng.uniform(2, 10, (50, 1)) + rng.normal(scale=0.5, size=(50, 3))
    px = cam.project(pts, w, h)
    assert np.all(np.isfinite(px))
    for p, (x, y) in zip(pts, px):
        o, d = cam.ray(x, y, w, h)
        assert np.isclose(np.linalg.norm(d), 1.0)
        v = p - o
        assert np.linalg.norm(v - d * (v @ d)) < 1e-6  # the point lies on the ray
        assert v @ d > 0


def test_centre_pixel_ray_is_forward_and_corner_is_top_left():
    cam = OrbitCamera(yaw=0.4, pitch=0.5)
    o, d = cam.ray(320, 240, 640, 480)
    assert np.allclose(o, cam.eye) and np.allclose(d, cam.forward)
    _, d00 = cam.ray(0, 0, 640, 480)
    assert d00 @ cam.up > 0 and d00 @ cam.right < 0


def test_ray_rejects_bad_input():
    cam = OrbitCamera()
    with pytest.raises(ValueError):
        cam.ray(float("nan"), 0.0, 10, 10)
    with pytest.raises(ValueError):
        cam.ray(0.0, 0.0, 0, 10)


def test_point_behind_camera_projects_to_nan():
    cam = OrbitCamera()
    px = cam.project([cam.eye - cam.forward * 2.0, cam.target], 100, 100)
    assert np.all(np.isnan(px[0])) and np.allclose(px[1], [50, 50])


def test_orbit_pitch_and_zoom_are_clamped():
    cam = OrbitCamera(pitch=0.2, distance=5.0, ground=None)
    cam.orbit(0.0, 10.0)
    assert cam.pitch == cam.pitch_max
    cam.orbit(0.0, -10.0)
    assert cam.pitch == cam.pitch_min
    cam.orbit(4.0, 0.0)
    assert -math.pi <= cam.yaw < math.pi
    cam.zoom(1e6)
    assert cam.distance == cam.distance_max
    cam.zoom(1e-9)
    assert cam.distance == cam.distance_min
    with pytest.raises(ValueError):
        cam.zoom(0.0)


def test_phone_camera_identity_and_looking_at():
    cam = PhoneCamera(position=np.array([0.0, 1.5, 0.0]))
    assert np.allclose(cam.forward, [0, 0, -1]) and np.allclose(cam.up, [0, 1, 0])
    cam2 = PhoneCamera.looking_at([3.0, 2.0, 3.0], [0.0, 1.0, 0.0])
    expect = np.array([-3.0, -1.0, -3.0]) / np.linalg.norm([3.0, 1.0, 3.0])
    assert np.allclose(cam2.forward, expect)
    assert np.allclose(cam2.project([[0.0, 1.0, 0.0]], 200, 100), [[100, 50]])
    assert abs(cam2.right[1]) < 1e-9  # no roll


def test_orbit_eye_never_goes_below_the_ground():
    rng = np.random.default_rng(3)
    cam = OrbitCamera(target=np.array([0.0, 0.6, 0.0]), pitch=0.5, distance=9.0)
    lowest = np.inf
    for _ in range(400):
        move = rng.integers(3)
        if move == 0:
            cam.orbit(rng.normal(0.0, 0.5), rng.normal(-0.1, 0.4))  # drags mostly downward
        elif move == 1:
            cam.zoom(float(np.exp(rng.normal(0.0, 0.6))))
        else:
            cam.pan(rng.normal(0.0, 1.0), rng.normal(-0.5, 1.0))
        eye = cam.eye
        lowest = min(lowest, eye[1])
        assert eye[1] >= cam.ground + cam.clearance - 1e-9
        assert cam.target[1] >= cam.ground
        # The view stays consistent: the eye looks at the target along its forward axis.
        to_target = cam.target - eye
        assert np.allclose(to_target / np.linalg.norm(to_target), cam.forward)
        assert np.allclose(cam.view_matrix(), look_at(eye, cam.target), atol=1e-9)
    assert lowest == pytest.approx(cam.ground + cam.clearance)  # the floor was reached, not avoided


def test_orbit_floor_applies_to_a_target_assigned_directly_and_lets_go_at_once():
    cam = OrbitCamera(target=np.array([0.0, 0.9, 0.0]), pitch=0.3, distance=5.0)
    cam.orbit(0.0, -10.0)
    floor = cam.pitch
    assert floor > cam.pitch_min and cam.eye[1] == pytest.approx(0.1)
    cam.orbit(0.0, 0.05)  # dragging back up moves the eye at once: no dead zone below the floor
    assert cam.pitch == pytest.approx(floor + 0.05) and cam.eye[1] > 0.1 + 0.1
    cam.target = np.array([0.0, 0.0, 0.0])  # a follow camera writing its target
    cam.distance = 2.0
    cam.pitch = -0.2
    assert cam.eye[1] >= 0.1 - 1e-12
