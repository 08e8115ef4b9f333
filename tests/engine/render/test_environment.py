"""Headless GL: the field's look, checked in pixels — conifers, the snow track, footprints, the horizon.

Runs on moderngl's EGL standalone context (Mesa llvmpipe); skipped with the reason where
no EGL GL 3.3 context can be made. Images are small to keep the tests fast.
"""

import numpy as np
import pytest

from engine.camera import OrbitCamera
from engine.render import RenderScene
from engine.render.headless import egl_available
from engine.render.scene import GroundMarks
from games.snowman.scenery import TREES, draw_trees

W, H = 320, 240

_reason = egl_available()
pytestmark = pytest.mark.skipif(_reason is not None, reason=f"no headless EGL OpenGL 3.3 context: {_reason}")


@pytest.fixture(scope="module")
def gl():
    from engine.render import Viewer, make_target

    viewer = Viewer(make_target(True, W, H, samples=0))
    yield viewer
    viewer.close()


def draw(viewer, scene, camera):
    viewer.camera = camera
    viewer.draw(scene)
    return viewer.read_pixels().astype(np.int32)


def field():
    """An empty snow field as the snowman game draws it (no grid lines)."""
    scene = RenderScene()
    scene.ground.grid = False
    return scene


def luminance(image):
    return image @ np.array([0.3, 0.59, 0.11])


def test_a_tree_has_the_pointed_silhouette_of_a_conifer(gl):
    x, z, s = TREES[0]
    side = OrbitCamera(target=np.array([x, 2.0 * s, z]), yaw=0.0, pitch=0.0, distance=9.0 * s)
    plain = draw(gl, field(), side)
    scene = field()
    draw_trees(scene)
    tree = np.abs(draw(gl, scene, side) - plain).sum(axis=2) > 40
    rows = np.nonzero(tree.any(axis=1))[0]
    width = tree.sum(axis=1)
    top, bottom = rows[0], rows[-1]
    assert bottom - top > 0.5 * H  # the tree fills the view's height
    widest = width.max()
    # Pointed: the top tenth of the tree is a narrow spire (round tiers, the old "green
    # snowman", were half as wide as the tree there).
    spire = width[top : top + (bottom - top) // 10]
    assert spire.max() < 0.2 * widest
    # Whorls: going down, the width grows, then steps back in where a tier's skirt ends
    # above the next tier (at least two such steps).
    profile = width[top:bottom]
    steps = np.sum((profile[:-4] - profile[4:]) > 0.08 * widest)
    assert steps >= 2


def _track_scene():
    """A ball's track rolled across the field, as the game draws it (cell 0.15 m)."""
    from games.snowman.snow import SnowField

    snow = SnowField(size=8.0, cell=0.15, initial_depth=0.12)
    snow.roll(np.array([-3.0, 0.0, 0.0]), np.array([3.0, 0.0, 0.0]), 0.3)
    scene = field()
    taken = 1.0 - snow.depth / snow.initial_depth
    scene.marks = GroundMarks(taken.T.astype(np.float32), -snow.size / 2, -snow.size / 2, snow.cell)
    return scene


def test_a_rolled_ball_leaves_a_soft_continuous_groove(gl):
    cam = OrbitCamera(target=np.array([0.0, 0.0, 0.0]), yaw=0.0, pitch=1.2, distance=6.0)
    plain = luminance(draw(gl, field(), cam))
    track = luminance(draw(gl, _track_scene(), cam))
    darker = plain - track
    # Along the track's middle (z = 0) every pixel between its ends is darker than fresh
    # snow: no gaps, no scales. Sampled away from the ends (x in [-2.5, 2.5]).
    xs = np.linspace(-2.5, 2.5, 41)
    px = np.round(cam.project(np.c_[xs, np.zeros_like(xs), np.zeros_like(xs)], W, H)).astype(int)
    along = darker[px[:, 1], px[:, 0]]
    assert along.min() > 4 and along.mean() > 8
    # Across it (a column through the middle) the shade comes and goes over several pixels:
    # soft edges, no pixel-to-pixel jump of more than a third of the groove's depth.
    x0, y0 = px[20]
    column = darker[max(y0 - 30, 0) : y0 + 30, x0]
    assert np.abs(np.diff(column)).max() < 0.35 * (column.max() - column.min())
    # Fresh snow beside the track is untouched.
    beside = np.round(cam.project(np.array([[0.0, 0.0, 1.2]]), W, H)).astype(int)[0]
    assert abs(darker[beside[1], beside[0]]) < 2


def test_footprints_darken_the_snow_where_they_lie(gl):
    cam = OrbitCamera(target=np.array([0.0, 0.0, 0.0]), yaw=0.0, pitch=1.1, distance=3.0)
    plain = luminance(draw(gl, field(), cam))
    scene = field()
    at = np.array([[-0.6, 0.1], [-0.2, -0.1], [0.2, 0.1], [0.6, -0.1]])
    scene.add_prints(at, 0.0)
    printed = luminance(draw(gl, scene, cam))
    px = np.round(cam.project(np.c_[at[:, 0], np.zeros(4), at[:, 1]], W, H)).astype(int)
    for x, y in px:
        assert plain[y, x] - printed[y, x] > 6, f"no footprint at pixel {x},{y}"
    # Between the prints the snow is as it was.
    mid = np.round(cam.project(np.array([[0.0, 0.0, 0.45]]), W, H)).astype(int)[0]
    assert abs(plain[mid[1], mid[0]] - printed[mid[1], mid[0]]) < 2


def test_the_horizon_is_a_line_one_can_see(gl):
    cam = OrbitCamera(target=np.array([0.0, 1.5, 0.0]), yaw=0.3, pitch=0.02, distance=6.0)
    rows = luminance(draw(gl, field(), cam)).mean(axis=1)
    horizon = int(np.round(cam.project(np.array([[0.0, 0.0, -1e4]]), W, H)[0, 1]))
    assert 10 < horizon < H - 10
    # Just above the far snow, the ridge's forest is a dark band between sky and snow.
    band = rows[horizon - 12 : horizon + 2].min()
    assert rows[: horizon - 25].mean() - band > 40  # sky above is far brighter
    assert rows[horizon + 20 :].mean() - band > 40  # and so is the snow below


@pytest.mark.parametrize("towards", [1.0, -1.0])
def test_the_groove_wall_facing_the_sun_is_the_brighter_one(gl, towards):
    """The track's walls are shaded by how they face the sun (``groove_shade``): with the sun low
    over +z the wall on the -z side, which faces +z, is lit and the other is in shade, and the
    other way round. (Broken once: with the slope's sign flipped in ``groove_shade`` this fails.)"""
    cam = OrbitCamera(target=np.array([0.0, 0.0, 0.0]), yaw=0.0, pitch=1.45, distance=3.0)
    scene = _track_scene()
    scene.sun.direction = (0.0, 0.45, 0.9 * towards)
    scene.sun.shadows = False
    img = luminance(draw(gl, scene, cam))
    # Sample across the groove (half-width 0.3 m) at x = 0: the wall around |z| = 0.25.
    zs = np.linspace(-0.45, 0.45, 19)
    px = np.round(cam.project(np.c_[np.zeros_like(zs), np.zeros_like(zs), zs], W, H)).astype(int)
    profile = img[px[:, 1], px[:, 0]]
    minus_side, plus_side = profile[:9].max(), profile[10:].max()
    lit, shaded = (minus_side, plus_side) if towards > 0 else (plus_side, minus_side)
    assert lit > shaded + 4


def test_the_ground_fills_the_view_only_when_every_corner_ray_lands_within_reach():
    """Looking down at the field the sky is skipped; raise the camera's pitch towards the horizon, turn it
    away from the field's centre, or bring the reach in, and it is not. (Checking only the view's centre
    ray, not its corners, fails the tilted case.)"""
    from engine.render.environment import ground_fills_view

    def fills(camera, reach=117.0, height=0.0):
        inv = np.linalg.inv(camera.view_projection(W / H))
        return ground_fills_view(inv, camera.eye, height, reach)

    down = OrbitCamera(target=np.array([0.0, 0.0, 0.0]), yaw=0.3, pitch=0.6, distance=9.0)
    assert fills(down)
    assert not fills(down, reach=5.0)  # the far corners land beyond 5 m
    assert not fills(down, height=down.eye[1] + 1.0)  # the eye under the plane sees no ground below it
    # The centre ray still lands close by, but the top corners reach the horizon.
    assert not fills(OrbitCamera(target=np.array([0.0, 0.0, 0.0]), yaw=0.3, pitch=0.2, distance=9.0))
    assert not fills(OrbitCamera(target=np.array([0.0, 1.0, 0.0]), yaw=0.3, pitch=0.05, distance=9.0))


@pytest.mark.parametrize("pitch", [0.6, 0.05])
def test_skipping_the_hidden_sky_changes_no_pixel(gl, pitch, monkeypatch):
    """The frame with the sky skipped where the ground hides it is the frame with the sky drawn, looking
    down (skipped) and at the horizon (drawn: its top is the sky's deeper blue, not the pale colour
    the frame is cleared to). (Skipping the sky in every frame fails the horizon case.)"""
    import engine.render.renderer as renderer_module

    scene = field()
    draw_trees(scene)
    camera = OrbitCamera(target=np.array([0.0, 1.0, 0.0]), yaw=0.3, pitch=pitch, distance=9.0)
    skipped = draw(gl, scene, camera)
    monkeypatch.setattr(renderer_module, "ground_fills_view", lambda *a: False)
    drawn = draw(gl, scene, camera)
    assert np.array_equal(skipped, drawn)
    sky = drawn[: H // 8]
    if pitch < 0.1:
        assert sky[..., 0].mean() < 175, "the horizon view should show the sky at the top"  # cleared: ~192
