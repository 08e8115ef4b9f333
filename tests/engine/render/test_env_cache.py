"""The sky and ground of a still view are drawn once and copied into the next frames.

Each frame is compared with the same scene drawn by a renderer that keeps nothing (the view key
made ``None``: clear, objects, then sky and ground behind the early depth test, as before the
cache): the copy must give the same pixels while a puppet moves and its shadow with it, and a
moved camera or a turned sun must draw the view again.
"""

import numpy as np
import pytest

from engine.camera import OrbitCamera
from engine.render import RenderScene
from engine.render.headless import egl_available
from engine.render.quality import QUALITIES

_reason = egl_available()
pytestmark = pytest.mark.skipif(_reason is not None, reason=f"no headless EGL OpenGL 3.3 context: {_reason}")

_CAMERA = OrbitCamera(target=np.array([0.0, 0.6, 0.0]), pitch=0.35, distance=6.0)
_MOVED = OrbitCamera(target=np.array([0.0, 0.6, 0.0]), yaw=0.3, pitch=0.35, distance=6.0)


def _scene(puppet_x: float, sun_y: float = 1.0) -> RenderScene:
    """A tree, a ball and a capsule (the puppet) standing a little above the snow, with shadows."""
    scene = RenderScene()
    scene.sun.direction = (0.4, sun_y, 0.3)
    scene.add_cones([[-2.0, 0.0, -1.0]], [[-2.0, 3.0, -1.0]], [0.6])
    scene.add_spheres(np.array([[1.5, 0.45, 0.5]]), np.array([0.4]))
    scene.add_capsule([puppet_x, 0.35, 0.3], [puppet_x, 1.5, 0.3], 0.25, (0.8, 0.2, 0.2))
    return scene


def _viewer(level: str):  # noqa: ANN202 - a Viewer, imported late (needs a context)
    from engine.render import Viewer, make_target

    viewer = Viewer(make_target(True, 320, 240, samples=0))
    with viewer.target.ctx:
        viewer.renderer.set_quality(QUALITIES[level])
    return viewer


def _uncached(scene: RenderScene, camera: OrbitCamera, level: str) -> np.ndarray:
    """``scene`` drawn by a new renderer that keeps no view (sky and ground drawn after the objects)."""
    from engine.render.renderer import Renderer

    viewer = _viewer(level)
    try:
        with pytest.MonkeyPatch.context() as patch:
            patch.setattr(Renderer, "_view_key", lambda *a: None)
            viewer.camera = camera
            viewer.draw(scene)
            return viewer.read_pixels().copy()
    finally:
        viewer.close()


@pytest.mark.parametrize("level", ["low", "medium"])
def test_a_still_view_is_drawn_once_and_each_frame_matches_a_renderer_that_keeps_nothing(level: str) -> None:
    """The puppet moves over three frames (one drawing of the view), then the camera moves and the sun
    turns (one more each).

    Broken once by copying the colour alone (the depth left from the last frame's objects): the
    puppet's old place hides the new one and its shadow, and the comparison fails; once by leaving
    the camera out of the key (``u_view_proj``, ``u_eye`` dropped): the moved camera's frame shows
    the old ground and fails; once by drawing the view anew every frame: the count fails.
    """
    viewer = _viewer(level)
    cache = viewer.renderer.env_cache
    frames = [(_scene(x), _CAMERA) for x in (-0.5, 0.0, 0.5)] + [(_scene(0.5), _MOVED), (_scene(0.5, 0.6), _MOVED)]
    stores = []
    try:
        for scene, camera in frames:
            viewer.camera = camera
            viewer.draw(scene)
            got = viewer.read_pixels()
            want = _uncached(scene, camera, level)
            assert np.array_equal(got, want), f"{np.count_nonzero(np.any(got != want, axis=2))} pixels differ"
            stores.append(cache.stores)
    finally:
        viewer.close()
    assert stores == [1, 1, 1, 2, 3]


def test_without_a_copy_the_view_is_drawn_every_frame_and_looks_the_same(monkeypatch: pytest.MonkeyPatch) -> None:
    """Where GL refuses the copy, the sky and ground are drawn in every frame, with the same pixels.

    Broken once by keeping the key after a refused copy (``store``): the key check fails. (A kept key
    is harmless here: ``restore``'s copy is refused too, and the frame is drawn.)"""
    import engine.render.env_cache as env_cache

    monkeypatch.setattr(env_cache, "blit", lambda *a: False)
    viewer = _viewer("low")
    try:
        for x in (-0.5, 0.5):
            scene = _scene(x)
            viewer.camera = _CAMERA
            viewer.draw(scene)
            assert viewer.renderer.env_cache.key is None
            assert np.array_equal(viewer.read_pixels(), _uncached(scene, _CAMERA, "low"))
    finally:
        viewer.close()


def test_a_ground_that_reads_the_shadow_mask_is_not_kept() -> None:
    """At ``high`` the snow is shaded per pixel and reads the moving casters' shadow mask itself: it
    cannot be kept (broken once by allowing it: the second frame keeps the first frame's shadow)."""
    viewer = _viewer("high")
    try:
        for x in (-0.5, 0.5):
            scene = _scene(x)
            viewer.camera = _CAMERA
            viewer.draw(scene)
            assert np.array_equal(viewer.read_pixels(), _uncached(scene, _CAMERA, "high"))
        assert viewer.renderer.env_cache.stores == 0
    finally:
        viewer.close()


def test_at_high_a_ground_without_a_shadow_is_kept() -> None:
    """At ``high`` with no caster the per-pixel snow reads no mask: it depends on the view alone and is
    kept like the lower levels' (one drawing for two frames, the same pixels as a renderer that keeps
    nothing); a caster then draws it every frame. Broken once by keying the ground's mask on detail
    alone (as before the split): nothing is kept and the count fails."""
    empty = RenderScene()
    viewer = _viewer("high")
    try:
        for scene in (empty, empty, _scene(0.0)):
            viewer.camera = _CAMERA
            viewer.draw(scene)
            assert np.array_equal(viewer.read_pixels(), _uncached(scene, _CAMERA, "high"))
        assert viewer.renderer.env_cache.stores == 1
    finally:
        viewer.close()


def test_a_detected_framebuffer_is_drawn_into_without_a_kept_view() -> None:
    """A window drawn into straight is a framebuffer moderngl detected: it lists no attachments
    (``None``), so the view is not kept for it and the frame is drawn as into any buffer. Broken
    once (reading its attachments as a list): ``author edit`` in a window crashed at its first frame."""
    from engine.render.env_cache import single_sampled

    scene = _scene(0.0)
    scene.ground.snow = 0.0  # a ground that could be kept (as in the authoring scenes)
    viewer = _viewer("high")  # full size: the scene is drawn into the target itself
    try:
        with viewer.target.ctx:
            made = viewer.target.framebuffer
            detected = viewer.target.ctx.detect_framebuffer(made.glo)
            assert detected.color_attachments is None
            assert not single_sampled(detected) and single_sampled(made)
            viewer.camera = _CAMERA
            viewer.renderer.render(scene, viewer.camera, detected)
            pixels = viewer.read_pixels().copy()
        expected = _uncached(scene, _CAMERA, "high")
        assert pixels.shape == expected.shape and pixels.std() > 5
        assert np.abs(pixels.astype(int) - expected.astype(int)).max() <= 2
    finally:
        viewer.close()
