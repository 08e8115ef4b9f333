"""Headless GL: the puppet shows where the camera projects it, shadows darken, overlays appear.

Runs on moderngl's EGL standalone context (Mesa llvmpipe); skipped with the reason where
no EGL GL 3.3 context can be made. Images are small to keep the tests fast.
"""

import numpy as np
import pytest

from engine import quat
from engine.camera import OrbitCamera, PhoneCamera
from engine.fk import forward_kinematics
from engine.humanoid import humanoid_skeleton
from engine.render import RenderScene, puppet_capsules
from engine.render.headless import egl_available

W, H = 320, 240

_reason = egl_available()
pytestmark = pytest.mark.skipif(_reason is not None, reason=f"no headless EGL OpenGL 3.3 context: {_reason}")


@pytest.fixture(scope="module")
def gl():
    from engine.render import Viewer, make_target

    viewer = Viewer(make_target(True, W, H, samples=0))
    yield viewer
    viewer.close()


def draw(viewer, scene, camera=None):
    if camera is not None:
        viewer.camera = camera
    viewer.draw(scene)
    return viewer.read_pixels().astype(np.int32)


def puppet_scene():
    sk = humanoid_skeleton()
    pos, rot = forward_kinematics(sk, sk.offsets[0], quat.identity(sk.num_joints))
    s = RenderScene()
    a, b, r, _ = puppet_capsules(sk, pos, rot)
    s.add_capsules(a, b, r, (0.8, 0.25, 0.2))
    return s, sk, pos


def test_puppet_pixels_differ_from_background(gl):
    cam = OrbitCamera(target=np.array([0.0, 0.9, 0.0]), yaw=0.3, pitch=0.25, distance=3.2)
    background = draw(gl, RenderScene(), cam)
    scene, sk, pos = puppet_scene()
    image = draw(gl, scene, cam)
    joints = [sk.index(n) for n in ("hips", "spine", "chest", "head", "l_lower_leg", "r_upper_leg")]
    px = np.round(cam.project(pos[joints], W, H)).astype(int)
    assert np.all((px >= 0) & (px < [W, H]))
    for x, y in px:
        diff = np.abs(image[y, x] - background[y, x]).sum()
        assert diff > 60, f"pixel {x},{y} looks like background"
        assert image[y, x, 0] > image[y, x, 2]  # reddish puppet
    # Far from the puppet (top corners: sky) nothing changed.
    assert np.abs(image[:10, :10] - background[:10, :10]).max() <= 2


def test_sphere_shadow_darkens_the_ground(gl):
    cam = OrbitCamera(target=np.array([0.0, 0.5, 0.0]), yaw=0.0, pitch=0.9, distance=5.0)
    base = RenderScene()
    base.sun.direction = (0.3, 1.0, 0.0)
    lit = draw(gl, base, cam)
    shadowed = RenderScene()
    shadowed.sun.direction = base.sun.direction
    centre = np.array([0.0, 1.2, 0.0])
    shadowed.add_sphere(centre, 0.35)
    dark = draw(gl, shadowed, cam)
    L = np.array(base.sun.direction) / np.linalg.norm(base.sun.direction)
    on_ground = centre - L * centre[1] / L[1]
    ((x, y),) = np.round(cam.project([on_ground], W, H)).astype(int)
    # the shadow spot is not covered by the sphere itself in this view
    ((sx, sy),) = cam.project([centre], W, H)
    assert np.hypot(x - sx, y - sy) > 25
    lum_lit, lum_dark = lit[y, x].sum(), dark[y, x].sum()
    assert lum_dark < 0.8 * lum_lit, (lum_lit, lum_dark)
    # Soft edge: half way out of the umbra is between shadow and light.
    ((ex, ey),) = np.round(cam.project([on_ground + [0.0, 0.0, 0.6]], W, H)).astype(int)
    assert dark[ey, ex].sum() > lum_dark


def test_shadows_can_be_switched_off(gl):
    cam = OrbitCamera(target=np.array([0.0, 0.5, 0.0]), pitch=0.9, distance=5.0)
    s = RenderScene()
    s.sun.direction = (0.0, 1.0, 0.0001)
    s.add_sphere([0.0, 1.2, 0.0], 0.35)
    with_shadow = draw(gl, s, cam)
    s.sun.shadows = False
    without = draw(gl, s, cam)
    ((x, y),) = np.round(cam.project([[0.0, 0.0, 0.0]], W, H)).astype(int)
    assert with_shadow[y, x].sum() < without[y, x].sum() - 30


def test_text_overlay_appears_where_placed(gl):
    cam = OrbitCamera()
    plain = draw(gl, RenderScene(), cam)
    s = RenderScene()
    s.add_text("FPS 60  walk", x=20, y=200, size=28, color=(1.0, 0.1, 0.1))
    texty = draw(gl, s, cam)
    changed = np.abs(texty - plain).sum(axis=2) > 40
    ys, xs = np.nonzero(changed)
    assert len(xs) > 50
    assert xs.min() >= 20 and ys.min() >= 200 and ys.max() < 200 + 30
    assert gl.renderer.text.texture("FPS 60  walk", 28, (1.0, 0.1, 0.1)) is gl.renderer.text.texture(
        "FPS 60  walk", 28, (1.0, 0.1, 0.1)
    )  # cached per string


def test_outline_rims_the_highlighted_capsule(gl):
    cam = OrbitCamera(target=np.array([0.0, 0.6, 0.0]), pitch=0.2, distance=3.0)
    plain, rimmed = RenderScene(), RenderScene()
    plain.add_capsule([0, 0.3, 0], [0, 1.0, 0], 0.15, (0.2, 0.3, 0.8))
    rimmed.add_capsule([0, 0.3, 0], [0, 1.0, 0], 0.15, (0.2, 0.3, 0.8), outline=True)
    rimmed.outline_color = (1.0, 0.0, 1.0)
    a, b = draw(gl, plain, cam), draw(gl, rimmed, cam)
    magenta = (b[..., 0] > 200) & (b[..., 1] < 60) & (b[..., 2] > 200)
    assert magenta.sum() > 100 and not ((a[..., 0] > 200) & (a[..., 1] < 60) & (a[..., 2] > 200)).any()
    # The rim lies outside the capsule's own pixels.
    inside = np.abs(a - draw(gl, RenderScene(), cam)).sum(axis=2) > 30
    assert (magenta & inside).sum() < 0.1 * magenta.sum()


def test_lines_and_pixel_points(gl):
    cam = PhoneCamera.looking_at([0.0, 1.0, 4.0], [0.0, 1.0, 0.0])
    s = RenderScene()
    s.ground.visible = False
    s.add_line([-1.0, 1.0, 0.0], [1.0, 1.0, 0.0], (0.0, 0.0, 0.0), width=3.0)
    s.add_points([[0.0, 1.6, 0.0]], 12.0, (0.0, 1.0, 0.0), pixels=True)
    img = draw(gl, s, cam)
    (lx, ly), (px, py) = np.round(cam.project([[0.5, 1.0, 0.0], [0.0, 1.6, 0.0]], W, H)).astype(int)
    assert img[ly, lx].sum() < 60
    assert img[py, px, 1] > 200 and img[py, px, 0] < 80


def test_background_photo_fades_with_the_sky(gl):
    cam = OrbitCamera(pitch=0.0)
    s = RenderScene()
    photo = np.zeros((60, 80, 3), dtype=np.uint8)
    photo[..., 0] = 255
    s.set_background(photo, fade=0.0)
    red = draw(gl, s, cam)
    assert red[5, W // 2, 0] > 200 and red[5, W // 2, 2] < 60
    s.background_fade = 1.0
    sky = draw(gl, s, cam)
    assert sky[5, W // 2, 2] > sky[5, W // 2, 0]


def test_screenshot_writes_png(gl, tmp_path):
    from PIL import Image

    scene, _, _ = puppet_scene()
    gl.draw(scene)
    out = gl.screenshot(tmp_path / "sub" / "shot.png")
    img = np.asarray(Image.open(out))
    assert img.shape == (H, W, 3) and np.array_equal(img, gl.read_pixels())


def test_objects_receive_shadows_from_objects(gl):
    cam = OrbitCamera(target=np.array([0.0, 0.5, 0.0]), pitch=1.0, distance=4.0)
    table = RenderScene()
    table.sun.direction = (0.0, 1.0, 0.0001)
    table.add_box([0.0, 0.25, 0.0], [1.0, 0.25, 1.0], color=(0.8, 0.8, 0.8))
    covered = RenderScene()
    covered.sun.direction = table.sun.direction
    covered.add_box([0.0, 0.25, 0.0], [1.0, 0.25, 1.0], color=(0.8, 0.8, 0.8))
    covered.add_sphere([0.0, 1.6, 0.0], 0.3)
    ((x, y),) = np.round(cam.project([[0.0, 0.5, 0.0]], W, H)).astype(int)
    ((sx, sy),) = cam.project([[0.0, 1.6, 0.0]], W, H)
    assert np.hypot(x - sx, y - sy) > 20  # the spot under the sphere is visible
    assert draw(gl, covered, cam)[y, x].sum() < 0.85 * draw(gl, table, cam)[y, x].sum()


def test_target_sizes_and_bad_input():
    from engine.render import make_target

    with pytest.raises(ValueError):
        make_target(True, 0, 10)
    t = make_target(True, 64, 32, samples=0)
    try:
        t.begin()
        t.end()
        assert t.read_pixels().shape == (32, 64, 3)
        t.resize(48, 40)
        assert t.size == (48, 40) and t.read_pixels().shape == (40, 48, 3)
    finally:
        t.close()


def test_solids_are_drawn_nearest_first_and_the_picture_does_not_depend_on_it(gl):
    from engine.render.renderer import _nearest_first

    eye = np.array([0.0, 1.0, 5.0])
    far, near = [0.0, 0.5, -3.0, 0.0, 1.5, -3.0], [0.0, 0.5, 2.0, 0.0, 1.5, 2.0]
    rows = np.array([far + [0.3, 1, 0, 0, 0], near + [0.3, 0, 1, 0, 0]], dtype=np.float32)
    assert np.array_equal(_nearest_first(rows, eye)[:, 2], [2.0, -3.0])
    # Two overlapping balls added in either order render the same picture.
    camera = OrbitCamera(target=np.array([0.0, 0.5, 0.0]), yaw=0.0, pitch=0.2, distance=4.0)
    balls = [(np.array([0.0, 0.5, 0.0]), (0.9, 0.2, 0.1)), (np.array([0.3, 0.5, 0.6]), (0.1, 0.2, 0.9))]
    images = []
    for order in (balls, balls[::-1]):
        s = RenderScene()
        for centre, color in order:
            s.add_sphere(centre, 0.5, color=color)
        images.append(draw(gl, s, camera))
    assert np.array_equal(images[0], images[1])
    assert (images[0][..., 2] > images[0][..., 0] + 100).sum() > 500  # the nearer blue ball shows


def test_a_viewer_draws_into_its_own_context_after_another_was_made(gl):
    import moderngl

    scene, _, _ = puppet_scene()
    camera = OrbitCamera(target=np.array([0.0, 0.9, 0.0]), yaw=0.3, pitch=0.25, distance=3.2)
    before = draw(gl, scene, camera)
    other = moderngl.create_standalone_context(backend="egl", require=330)  # now current
    try:
        assert np.array_equal(draw(gl, scene, camera), before)
    finally:
        other.release()
    assert np.array_equal(draw(gl, scene, camera), before)


def test_a_thin_caster_shades_the_ground_steadily_even_when_the_shadow_mask_is_coarse(gl):
    # Casters 20 m apart stretch the ground mask to ~8.6 cm texels; an 8 cm forearm moved
    # across one texel darkens the ground under it at every position (no flicker), and
    # with the casters close together (1.6 cm texels) its shadow is dark.
    cam = OrbitCamera(target=np.array([0.0, 0.0, 0.0]), yaw=0.0, pitch=1.2, distance=2.5)

    def ground_under_forearm(spread, x):
        scene = RenderScene()
        scene.sun.direction = (0.0, 1.0, 0.0001)
        scene.ground.grid = False
        scene.add_sphere([-spread, 0.5, 0.0], 0.5)
        scene.add_sphere([spread, 0.5, 0.0], 0.5)
        if x is not None:
            scene.add_capsule([x, 0.6, -0.3], [x, 0.6, 0.3], 0.04)
        ((px, py),) = np.round(cam.project([[0.0 if x is None else x, 0.0, 0.2]], W, H)).astype(int)
        return draw(gl, scene, cam)[py - 2 : py + 3, px - 2 : px + 3].sum(axis=2).mean()

    for spread, least in ((10.0, 0.05), (1.0, 0.25)):
        plain = ground_under_forearm(spread, None)
        darkening = np.array([1.0 - ground_under_forearm(spread, x) / plain for x in np.linspace(0.0, 0.086, 6)])
        assert darkening.min() > least, (spread, darkening)
        assert darkening.max() < 1.6 * darkening.min(), (spread, darkening)


@pytest.mark.parametrize("distance", [2.5, 6.0, 15.0])
def test_a_ball_does_not_shadow_its_own_sunlit_side(gl, distance):
    # Seen from the sun's side at any level of detail, the lit half looks the same with
    # shadows on and off: the shadow map's caster is never finer than the ball drawn.
    sun = np.array([0.6, 0.75, -0.1])
    cam = OrbitCamera(target=np.array([0.0, 0.6, 0.0]), yaw=np.arctan2(sun[0], sun[2]), pitch=0.5, distance=distance)
    images = []
    for shadows in (True, False):
        scene = RenderScene()
        scene.sun.direction, scene.sun.shadows = tuple(sun), shadows
        scene.ground.visible = False
        scene.add_sphere([0.0, 0.6, 0.0], 0.5)
        scene.add_sphere([-2.0, 0.3, 3.0], 0.3)  # a second caster widens the shadow map
        images.append(draw(gl, scene, cam))
    ((cx, cy),) = np.round(cam.project([[0.0, 0.6, 0.0]], W, H)).astype(int)
    radius_px = 0.5 * H / (2 * np.tan(np.radians(cam.fov_y) / 2)) / distance
    yy, xx = np.mgrid[0:H, 0:W]
    inner = np.hypot(xx - cx, yy - cy) < 0.6 * radius_px
    diff = np.abs(images[0] - images[1]).sum(axis=2)[inner]
    assert inner.sum() > 20 and diff.max() <= 6, (distance, diff.max())


def test_a_frame_after_the_camera_and_sun_moved_matches_a_fresh_renderers(gl):
    """The frame uniforms are written only when they change: a renderer that drew another view
    and sun first must still draw exactly what a new renderer draws. (Broken once: with no
    frame uniform ever written again after the first frame, the second view kept the first
    camera and this failed.)"""
    from engine.render import Viewer, make_target

    scene, _, _ = puppet_scene()
    scene.add_spheres([[0.6, 0.3, 0.3]], 0.3)
    first = OrbitCamera(target=np.array([0.0, 0.9, 0.0]), yaw=0.0, pitch=0.2, distance=4.0)
    second = OrbitCamera(target=np.array([0.2, 0.8, 0.0]), yaw=1.1, pitch=0.5, distance=3.0)
    draw(gl, scene, first)
    scene.sun.direction = (-0.4, 0.8, 0.3)
    again = draw(gl, scene, second)
    fresh = Viewer(make_target(True, W, H, samples=0))
    try:
        new = draw(fresh, scene, second)
    finally:
        fresh.close()
    assert np.abs(again - new).max() <= 2
    assert np.abs(again - draw(gl, scene, first)).mean() > 5  # the two views do differ
