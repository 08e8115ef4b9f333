"""The ground shadow's share of the light is set once per frame, not divided out on every pixel.

llvmpipe runs uniform-only arithmetic on every pixel, so the shadow decal (and the high ground's
``MASK``) read ``u_shadow_take``, made by :func:`~engine.render.environment.shadow_take`, and the
decal folds its fog into one division. The picture must stay the one the per-pixel formula drew.
"""

import numpy as np
import pytest

from engine.camera import OrbitCamera
from engine.render import RenderScene
from engine.render import shaders_ground as G
from engine.render.environment import SHADOW_STRENGTH, shadow_take
from engine.render.headless import egl_available
from tests.engine.render.drawn import drawn

_reason = egl_available()
needs_gl = pytest.mark.skipif(_reason is not None, reason=f"no headless EGL OpenGL 3.3 context: {_reason}")

W, H = 320, 240
_CAMERA = OrbitCamera(target=np.array([0.0, 0.5, -2.0]), yaw=0.3, pitch=0.35, distance=9.0)
"""Over a row of casters from near to 12 m away: their shadows at several fog distances."""

# The decal and the ground's mask read as they were, each pixel working out the sun's share.
_PER_PIXEL_DECAL = """
uniform sampler2D u_ground_mask;
in vec3 v_pos;
in vec2 v_uv;
out vec4 f_color;
void main() {
    float m = texture(u_ground_mask, v_uv).r;
    if (m < 0.004) discard;
    vec3 sun = u_sun_color * u_sun_dir.y;
    vec3 lit = sun / (sun + u_sky_lin * u_ambient * 1.6);
    vec3 keep = 1.0 - m * 0.9 * lit;
    keep = mix(keep, vec3(1.0), fog_amount(length(u_eye - v_pos)));
    f_color = vec4(0.5 * sqrt(keep), 1.0);
}
"""
_PER_PIXEL_MASK = """        vec3 sun = u_sun_color * u_sun_dir.y;
        c *= 1.0 - texture(u_ground_mask, muv).r * u_shadow_strength * sun / (sun + u_sky_lin * u_ambient * 1.6);"""


def _field(shadows: bool = True) -> RenderScene:
    scene = RenderScene()
    scene.ground.grid = False
    scene.sun.shadows = shadows
    z = np.linspace(3.0, -12.0, 6)
    scene.add_spheres(np.c_[np.full(6, 0.8), np.full(6, 0.5), z], np.full(6, 0.5))
    scene.add_capsules(np.c_[np.full(6, -0.8), np.full(6, 0.3), z], np.c_[np.full(6, -0.8), np.full(6, 1.6), z], 0.25)
    return scene


def _frame(scene: RenderScene, quality: str, per_pixel: bool) -> np.ndarray:
    with pytest.MonkeyPatch.context() as patch:
        if per_pixel:
            patch.setattr(G, "SHADOW_DECAL_FS", _PER_PIXEL_DECAL)
            line = "        c *= 1.0 - texture(u_ground_mask, muv).r * u_shadow_take;"
            assert line in G.GROUND_MESH_FS
            patch.setattr(G, "GROUND_MESH_FS", G.GROUND_MESH_FS.replace(line, _PER_PIXEL_MASK))
        return drawn(scene, _CAMERA, quality, (W, H))


@needs_gl
@pytest.mark.parametrize("quality", ["low", "medium", "high"])
def test_the_shadow_is_the_one_the_per_pixel_formula_drew(quality: str) -> None:
    """Casters from 3 m in front of the target to 12 m behind it (fog from ~0.1 to ~0.2), at each level:
    low and medium draw the shadow as a decal, high reads the mask in the ground.

    Broken once by leaving the fog out of the decal (``1.0 - m * u_shadow_take``): the far shadows grow
    darker (by 44 levels at most), and low and medium fail; once by dropping the sky's term from
    :func:`shadow_take` (the sun's share becomes 1): every shadow darkens and all three fail.
    """
    scene = _field()
    now = _frame(scene, quality, per_pixel=False)
    before = _frame(scene, quality, per_pixel=True)
    unshadowed = _frame(_field(shadows=False), quality, per_pixel=False)
    shadowed = np.count_nonzero(np.any(np.abs(before - unshadowed) > 8, axis=2))
    assert shadowed > 1500, f"only {shadowed} pixels in shadow: the scene does not test the shadow"
    diff = np.abs(now - before).max(axis=2)
    assert diff.max() <= 2, f"a pixel differs by {diff.max()} levels"
    assert np.count_nonzero(diff) <= 0.001 * W * H, f"{np.count_nonzero(diff)} pixels differ"


def test_the_share_taken_is_the_suns_share_of_the_light_times_the_strength() -> None:
    """No sky light: the shadow takes the whole of the strength; sky light equal to the sun's (after the
    ambient and the 1.6 of the snow's bounce): half of it; a blue sky keeps more blue in the shadow.

    Broken once by leaving the sky's term out of the sum (``sun / sun``): the second case takes the whole
    strength and it fails (so do the three pixel comparisons above).
    """
    common = {"u_sun_color": (2.0, 2.0, 2.0), "u_sun_dir": (0.0, 0.5, 0.0), "u_sky_lin": (0.0, 0.0, 0.0)}
    assert shadow_take({**common, "u_ambient": 0.5}) == pytest.approx((SHADOW_STRENGTH,) * 3)
    even = {**common, "u_sky_lin": (1.25, 1.25, 1.25), "u_ambient": 0.5}  # 1.25 · 0.5 · 1.6 = 1 = the sun's 2 · 0.5
    assert shadow_take(even, 0.6) == pytest.approx((0.3, 0.3, 0.3))
    red, _, blue = shadow_take({**common, "u_sky_lin": (0.2, 0.4, 0.9), "u_ambient": 0.45})
    assert blue < red
