"""BGRA-stored colour textures: same pixels as moderngl's own, the scale-up on llvmpipe's linear path, names freed."""

import ctypes

import numpy as np
import pytest

from engine.camera import OrbitCamera
from engine.render import RenderScene
from engine.render.headless import egl_available

_reason = egl_available()
pytestmark = pytest.mark.skipif(_reason is not None, reason=f"no headless EGL OpenGL 3.3 context: {_reason}")


def _low_frame(bgra: bool, monkeypatch: pytest.MonkeyPatch) -> tuple[np.ndarray, list[object]]:
    """The pixels of one scene at quality low drawn with (or without) BGRA textures, and the
    ``extra`` tags of the frame's and the small buffer's colour textures."""
    import engine.render.offscreen as offscreen
    import engine.render.renderer as renderer
    from engine.render.headless import HeadlessTarget
    from engine.render.quality import QUALITIES

    monkeypatch.setattr(offscreen, "is_software", lambda ctx: bgra)
    monkeypatch.setattr(renderer, "is_software", lambda ctx: bgra)
    target = HeadlessTarget(320, 180, samples=0)
    r = renderer.Renderer(target.ctx, QUALITIES["low"])
    try:
        scene = RenderScene()
        scene.add_capsule([0.0, 0.3, 0.0], [0.0, 1.5, 0.0], 0.3, (0.8, 0.2, 0.2))
        scene.add_spheres(np.array([[0.8, 0.3, 0.4]]), np.array([0.3]))
        scene.add_text("quality", x=4, y=4, size=18)
        camera = OrbitCamera(target=np.array([0.0, 0.9, 0.0]), pitch=0.2, distance=4.0)
        r.render(scene, camera, target.begin())
        target.end()
        assert r._scaled is not None
        tags = [target.buffers.resolved.color_attachments[0].extra, r._scaled[1].extra]
        return target.read_pixels(), tags
    finally:
        r.release()
        target.close()


def test_the_low_frame_is_the_same_with_bgra_textures(monkeypatch: pytest.MonkeyPatch) -> None:
    """The scale-up drawn BGRA to BGRA into the colour attachment alone gives the RGBA path's pixels.

    Broken once by drawing the scale-up into a colour-only framebuffer over a new texture
    instead of the frame's own attachment: both frames keep only the text (equal, but blank), and this fails.
    """
    rgba, plain = _low_frame(False, monkeypatch)
    bgra, owned = _low_frame(True, monkeypatch)
    assert plain == [None, None]
    assert owned == ["bgra-owned", "bgra-owned"]  # the BGRA storage was really made (not the fallback)
    assert np.array_equal(rgba, bgra)
    assert rgba[90, 160, 0] > rgba[90, 160, 2]  # the red capsule in the middle: not a blank frame


def test_a_released_bgra_texture_frees_its_gl_name() -> None:
    """moderngl leaves an external texture's name alone; :func:`release_texture` deletes it.

    Broken once by skipping the ``glDeleteTextures`` call: the name stays a texture.
    """
    from engine.render.bgra import colour_texture, release_texture
    from engine.render.headless import HeadlessTarget
    from engine.render.rawgl import gl as system_gl

    target = HeadlessTarget(16, 16, samples=0)
    try:
        gl = system_gl()
        assert gl is not None
        gl.glIsTexture.argtypes = [ctypes.c_uint]
        tex = colour_texture(target.ctx, (8, 4), True)
        name = tex.glo
        assert tex.extra == "bgra-owned" and tex.size == (8, 4)
        assert gl.glIsTexture(name)
        release_texture(tex)
        assert not gl.glIsTexture(name)
        plain = colour_texture(target.ctx, (8, 4), False)
        assert plain.extra is None
        release_texture(plain)
    finally:
        target.close()
