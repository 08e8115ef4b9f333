"""At quality high the ground's per-pixel snow is split into draws that pay only for what they show.

llvmpipe runs a branch's fetches and arithmetic on every pixel of a draw that holds it, taken or
not, so the fine snow (``NEAR``) is compiled only into the draw of the rings that come within
``NEAR_DETAIL`` of the eye, and the shadow mask (``MASK``) only when there is a shadow. The frame
must be the frame of the single draw with both, pixel for pixel, and still show the fine snow.
"""

from collections.abc import Callable

import numpy as np
import pytest

from engine.camera import OrbitCamera
from engine.render import RenderScene
from engine.render.environment import Environment
from engine.render.headless import egl_available
from engine.render.shaders_ground import NEAR_DETAIL
from tests.engine.render.drawn import drawn

_reason = egl_available()
pytestmark = pytest.mark.skipif(_reason is not None, reason=f"no headless EGL OpenGL 3.3 context: {_reason}")

W, H = 320, 240
_LOW_CAMERA = OrbitCamera(target=np.array([0.0, 0.4, 0.0]), yaw=0.2, pitch=0.12, distance=5.0)
"""Low over the snow: the near snow at the bottom, far snow and the sky above."""


def _field(shadow: bool) -> RenderScene:
    scene = RenderScene()
    scene.ground.grid = False
    if shadow:
        scene.add_spheres(np.array([[0.5, 0.5, 0.0]]), np.array([0.5]))
        scene.add_capsule([-0.8, 0.3, 0.4], [-0.8, 1.6, 0.4], 0.25, (0.8, 0.2, 0.2))
    return scene


def _one_draw_with_everything(self: Environment, detail: bool, grid: bool, photo: bool, uniforms: dict) -> list:
    """The ground as one draw whose program holds the near snow and the mask read (as before the split)."""
    draws = _SPLIT(self, detail, grid, photo, uniforms)
    if not detail:
        return draws
    features = ("PIXEL", "NEAR", "MASK", *(f for f, on in (("GRID", grid), ("PHOTO", photo)) if on))
    return [(self._ground_variant(features), 0, sum(count for _, _, count in draws))]


_SPLIT: Callable[..., list] = Environment.ground_draws


def _frame(scene: RenderScene, camera: OrbitCamera, one_draw: bool) -> np.ndarray:
    with pytest.MonkeyPatch.context() as patch:
        if one_draw:
            patch.setattr(Environment, "ground_draws", _one_draw_with_everything)
        return drawn(scene, camera, "high", (W, H))


@pytest.mark.parametrize("shadow", [False, True])
def test_the_split_ground_draws_the_same_pixels_as_one_draw_with_all_its_detail(shadow: bool) -> None:
    """Low over the snow (near snow, far snow, sky), with and without casters.

    Broken once by splitting one band further out than the bound (``near_bands - 2``): pixels of the
    near snow lose their drifts and sparkle and the comparison fails; once by leaving the mask out
    with a shadow present: the shadow is gone and it fails.
    """
    scene = _field(shadow)
    split = _frame(scene, _LOW_CAMERA, one_draw=False)
    whole = _frame(scene, _LOW_CAMERA, one_draw=True)
    differ = np.count_nonzero(np.any(split != whole, axis=2))
    assert differ == 0, f"{differ} pixels differ"


def test_only_the_rings_within_reach_of_the_eye_get_the_near_snow() -> None:
    """The near draw ends at the first band whose chords all lie beyond ``NEAR_DETAIL``; the mask is read
    only with a shadow, and only up to the first band beyond the farthest corner of its rectangle.
    Broken once by counting bands by their outer ring: the bound check fails; once by measuring the
    rectangle to its nearest corner: the mask's bound check fails."""
    from engine.render import make_target

    target = make_target(True, 8, 8, samples=0)
    try:
        env = Environment(target.ctx)
        extent = 150.0
        draws = env.ground_draws(True, False, False, {"u_extent": extent, "u_shadow_strength": 0.0})
        (near, first, count), (far, rest, count_far) = draws
        assert near == "ground_pixel_near" and far == "ground_pixel" and first == 0 and rest == count
        bands = env._ring_bands * extent  # least distance of each band from the centre
        band = count // env._band_indices  # the first band drawn without the near snow
        assert bands[band] >= NEAR_DETAIL > bands[band - 1]
        assert count + count_far == len(bands) * env._band_indices
        shadow = {
            "u_extent": extent,
            "u_shadow_strength": 0.9,
            "u_rect": (-3.0, 10.0, 6.0, 14.0),
            "u_center": (0, 0, 0),
        }
        shadowed = env.ground_draws(True, False, False, shadow)
        assert [k for k, _, _ in shadowed] == ["ground_pixel_near_mask", "ground_pixel_mask", "ground_pixel"]
        masked = (shadowed[0][2] + shadowed[1][2]) // env._band_indices  # the first band drawn without the mask
        corner = np.hypot(3.0, 24.0)  # the rectangle's farthest corner from the centre
        assert bands[masked] >= corner > bands[masked - 1]
        assert sum(count for _, _, count in shadowed) == len(bands) * env._band_indices
        plain = env.ground_draws(False, False, False, {"u_extent": extent, "u_shadow_strength": 0.9})
        assert [k for k, _, _ in plain] == ["ground"]
        env.release()
    finally:
        target.close()


def _without_near_snow(self: Environment, detail: bool, grid: bool, photo: bool, uniforms: dict) -> list:
    """The split ground with the near snow left out of every band."""
    draws = _SPLIT(self, detail, grid, photo, uniforms)
    kept = [tuple(f.upper() for f in key.split("_")[1:] if f != "near") for key, _, _ in draws]
    return [(self._ground_variant(f), first, count) for f, (_, first, count) in zip(kept, draws, strict=True)]


def test_the_near_snow_still_shows_near_the_eye_and_nowhere_else(monkeypatch: pytest.MonkeyPatch) -> None:
    """Pixel statistics of the empty field at high against the same field with the near snow left out:
    its drifts and sparkle change most pixels of the bottom rows (the snow within a few metres), a
    sparkle stands out somewhere, and the far half of the ground and the sky do not change at all.

    The snow is nearly white, so the drifts move a pixel by 1-2 levels; a sparkle by 10 or more.
    Broken once by drawing every band without the near snow (``near_bands = 0``): no pixel changes
    and it fails.
    """
    detailed = _frame(_field(False), _LOW_CAMERA, one_draw=False)
    monkeypatch.setattr(Environment, "ground_draws", _without_near_snow)
    plain = _frame(_field(False), _LOW_CAMERA, one_draw=False)
    change = np.abs(detailed - plain).max(axis=2)
    assert (change[int(0.85 * H) :] > 0).mean() > 0.5
    assert change.max() >= 8  # a sparkle
    assert not change[: int(0.45 * H)].any()  # the far snow, the ridge and the sky
