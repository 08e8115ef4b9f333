"""Stroke fits (Eq. 3.6), principal curves (Eq. 3.1), abstract contours (Eq. 3.2–3.5)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from authoring.flowcurves.contours import THIN, abstract_contour, outside_count, thinness
from authoring.flowcurves.hermite import control_count, fit_stroke
from authoring.flowcurves.principal import principal_curve


def test_control_points_follow_the_thesis_rule() -> None:
    assert control_count(1280 / 4, 1280) == 4  # a quarter of the screen: ⌈3⌉ + 1
    assert control_count(1280, 1280) == 13


def test_stroke_fit_keeps_a_bend_and_smooths_a_wiggle() -> None:
    t = np.linspace(0, np.pi, 60)
    arc = np.c_[200 * np.cos(t), 200 * np.sin(t)]
    assert np.abs(np.linalg.norm(fit_stroke(arc, 1280).sample(80), axis=1) - 200).max() < 2.0
    x = np.linspace(0, 600, 300)
    wiggly = np.c_[x, 3 * np.sin(x / 40 * 2 * np.pi)]
    assert np.abs(fit_stroke(wiggly, 1280).sample(100)[:, 1]).max() < 2.0


@settings(max_examples=40, deadline=None)
@given(st.lists(st.tuples(st.floats(-1e4, 1e4), st.floats(-1e4, 1e4)), min_size=0, max_size=30))
def test_stroke_fit_never_crashes(points: list[tuple[float, float]]) -> None:
    try:
        curve = fit_stroke(np.array(points, dtype=np.float64).reshape(-1, 2), 1280)
    except ValueError:
        return
    assert np.all(np.isfinite(curve.q))


def _band(curve_x, n: int = 600, width: float = 6.0) -> np.ndarray:  # type: ignore[no-untyped-def]
    rng = np.random.default_rng(3)
    y = rng.uniform(0, 300, n)
    return np.c_[curve_x(y) + rng.uniform(-width, width, n), y]


def test_principal_curve_follows_a_bent_band() -> None:
    bend = lambda y: 100 + 0.002 * (y - 150) ** 2  # noqa: E731
    curve = principal_curve(_band(bend))
    p = curve.sample(50)
    inner = p[(p[:, 1] > 20) & (p[:, 1] < 280)]
    assert np.abs(inner[:, 0] - bend(inner[:, 1])).mean() < 3.0


def test_contour_encloses_its_outline_and_is_not_the_box() -> None:
    t = np.linspace(0, 2 * np.pi, 120, endpoint=False)
    disc = np.c_[300 + 50 * np.cos(t), 200 + 50 * np.sin(t)]
    contour = abstract_contour(disc)
    poly = contour.sample(64)
    assert outside_count(poly, disc) == 0
    q = np.roll(poly, -1, axis=0)
    area = abs(np.sum(poly[:, 0] * q[:, 1] - poly[:, 1] * q[:, 0])) / 2
    assert np.pi * 50**2 <= area < 0.97 * 106**2  # shrunk from the (padded) box towards the disc


@pytest.mark.parametrize("thin", [True, False])
def test_thinness_tells_a_pole_from_a_pine(thin: bool) -> None:
    """A pole keeps its principal curve; a pine's outline (wide base, narrow top) its contour."""
    rng = np.random.default_rng(0)
    y = rng.uniform(0, 300, 800)
    half = np.full_like(y, 4.0) if thin else 5.0 + 60.0 * y / 300
    pts = np.c_[200 + rng.uniform(-1, 1, 800) * half, y]
    edge = np.r_[np.c_[200 - half, y], np.c_[200 + half, y]]
    assert (thinness(principal_curve(pts), abstract_contour(edge)) < THIN) is thin
