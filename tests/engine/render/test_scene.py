"""RenderScene: buffers grow and keep capacity, builders broadcast, bad input adds nothing."""

import numpy as np
import pytest

import engine.render as render
from engine.render.scene import CAPSULE_STRIDE, RenderScene, Rows


def test_rows_grow_and_clear_keeps_capacity():
    rows = Rows(3, capacity=2)
    for i in range(100):
        rows.extend(1)[:] = i
    assert len(rows) == 100 and rows.data[57, 0] == 57
    cap = rows._data.shape[0]
    rows.clear()
    assert len(rows) == 0 and rows._data.shape[0] == cap


def test_add_capsules_broadcasts_one_colour_and_radius():
    s = RenderScene()
    a = np.zeros((4, 3))
    b = np.ones((4, 3))
    s.add_capsules(a, b, 0.1, (1.0, 0.5, 0.0), outline=True)
    d = s.capsules.data
    assert d.shape == (4, CAPSULE_STRIDE) and d.dtype == np.float32
    assert np.allclose(d[:, 3:6], 1) and np.allclose(d[:, 6], 0.1)
    assert np.allclose(d[:, 7:10], [1.0, 0.5, 0.0]) and np.all(d[:, 10] == 1)


def test_sphere_is_a_capsule_with_equal_ends():
    s = RenderScene()
    s.add_spheres([[1, 2, 3], [4, 5, 6]], [0.5, 0.25])
    d = s.spheres.data
    assert np.allclose(d[:, 0:3], d[:, 3:6]) and np.allclose(d[:, 6], [0.5, 0.25])


@pytest.mark.parametrize(
    "call",
    [
        lambda s: s.add_capsules(np.zeros((3, 3)), np.zeros((2, 3)), 0.1),
        lambda s: s.add_capsules(np.zeros((3, 3)), np.zeros((3, 3)), -0.1),
        lambda s: s.add_spheres([[0, 0, 0]], float("nan")),
        lambda s: s.add_lines(np.zeros((2, 3)), np.zeros((3, 3))),
        lambda s: s.add_points(np.zeros((2, 3)), [1.0, 2.0, 3.0]),
        lambda s: s.add_boxes([0, 0, 0], [1, -1, 1]),
        lambda s: s.add_text("x", size=0),
        lambda s: s.add_text(42),
    ],
)
def test_bad_input_raises_and_adds_nothing(call):
    s = RenderScene()
    s.add_capsule([0, 0, 0], [0, 1, 0], 0.1)
    with pytest.raises((ValueError, TypeError)):
        call(s)
    assert len(s.capsules) == 1 and len(s.spheres) == 0 and len(s.lines) == 0
    assert len(s.points) == 0 and len(s.boxes) == 0 and not s.texts


def test_polyline_points_and_text():
    s = RenderScene()
    s.add_polyline(np.c_[np.arange(5), np.zeros(5), np.zeros(5)], closed=True)
    assert len(s.lines) == 5
    s.add_points(np.zeros((7, 3)), 6.0, pixels=True)
    assert np.all(s.points.data[:, 7] == 1.0) and np.all(s.points.data[:, 3] == 6.0)
    s.add_text("fps 60")
    s.add_text("state: walk", x=100, y=20, size=24, color=(1, 0, 0))
    assert [t.text for t in s.texts] == ["fps 60", "state: walk"]
    s.clear()
    assert len(s.lines) == len(s.points) == 0 and not s.texts


def test_bounds_cover_every_caster():
    s = RenderScene()
    assert s.bounds() is None
    s.add_capsule([0, 0, 0], [0, 2, 0], 0.1)
    s.add_sphere([3, 1, 0], 0.5)
    s.add_box([-2, 0.5, 0], [0.5, 0.5, 0.5])
    lo, hi = s.bounds()
    assert lo[0] <= -2.5 and hi[0] >= 3.5 - 1e-6 and hi[1] >= 2.1 - 1e-6 and lo[1] <= -0.1 + 1e-6


def test_bounds_of_a_crowd_are_its_rows_reach_to_the_bit():
    """Reduced by columns per kind, the bounds are exactly the row-by-row reach (a swapped end, a radius
    added on the wrong side or a kind left out fails)."""
    rng = np.random.default_rng(5)
    s = RenderScene()
    s.add_capsules(rng.normal(size=(3000, 3)) * 20, rng.normal(size=(3000, 3)) * 20, rng.uniform(0.01, 0.3, 3000))
    s.add_spheres(rng.normal(size=(40, 3)) * 30, rng.uniform(0.1, 2.0, 40))
    s.add_cones(rng.normal(size=(9, 3)) * 40, rng.normal(size=(9, 3)) * 40, rng.uniform(0.5, 3.0, 9))
    rows = np.vstack([s.capsules.data, s.spheres.data, s.cones.data])
    lo, hi = s.bounds()
    assert np.array_equal(lo, (np.minimum(rows[:, 0:3], rows[:, 3:6]) - rows[:, 6:7]).min(axis=0))
    assert np.array_equal(hi, (np.maximum(rows[:, 0:3], rows[:, 3:6]) + rows[:, 6:7]).max(axis=0))


def test_background_validation_and_fade():
    s = RenderScene()
    img = np.zeros((4, 6, 3), dtype=np.uint8)
    s.set_background(img, fade=0.3)
    assert s.background is not None and s.background_fade == 0.3
    with pytest.raises(ValueError):
        s.set_background(np.zeros((4, 6), dtype=np.uint8))
    with pytest.raises(ValueError):
        s.set_background(np.zeros((4, 6, 3)), fade=0.5)
    with pytest.raises(ValueError):
        s.set_background(img, fade=2.0)
    assert s.background is img or np.shares_memory(s.background, img)
    s.set_background(None)
    assert s.background is None


def test_public_surface():
    for name in render.__all__:
        assert getattr(render, name) is not None
    with pytest.raises(AttributeError):
        render.nope  # noqa: B018  # the access itself must raise
