"""Looping Bézier fits within their error bound."""

from __future__ import annotations

import numpy as np
import pytest

from authoring.cycles.spline import fit_item
from authoring.cycles.stitch import rotation_angle
from authoring.cycles.trajectory import Item
from engine import quat


def test_position_loop_fits_within_bound_and_is_closed() -> None:
    s = 120
    ph = np.arange(s) / s
    loop = np.stack([np.sin(2 * np.pi * ph), np.cos(4 * np.pi * ph) * 0.5, 0.2 * np.sin(6 * np.pi * ph)], axis=1)
    fit = fit_item(Item("p", "position", 0, 3), loop, period=1.2, tolerance=0.002)
    assert fit.max_error <= 0.002 * 2.0  # bound is relative to the range (2.0)
    t = ph * 1.2
    assert np.max(np.abs(fit.evaluate(t) - loop)) == pytest.approx(fit.max_error)
    assert np.allclose(fit.evaluate(0.0), fit.evaluate(1.2))  # periodic
    assert 4 <= fit.segments < s  # smoothing, not one segment per sample
    # The Bézier segments join: the end of one is the start of the next.
    assert np.allclose(fit.control[:-1, 3], fit.control[1:, 0])
    assert np.allclose(fit.control[-1, 3], fit.control[0, 0])


def test_tighter_bound_needs_more_segments() -> None:
    s = 200
    ph = np.arange(s) / s
    loop = np.sin(2 * np.pi * ph[:, None] * np.array([1, 3, 5]))
    loose = fit_item(Item("a", "scalar", 0, 3), loop, 1.0, tolerance=0.05)
    tight = fit_item(Item("a", "scalar", 0, 3), loop, 1.0, tolerance=0.001)
    assert tight.segments > loose.segments
    assert tight.max_error <= 0.001 * 2.0


def test_rotation_fit_in_tangent_space() -> None:
    s = 90
    ph = np.arange(s) / s
    loop = quat.from_axis_angle(np.array([0.2, 1.0, 0.0]), 1.2 * np.sin(2 * np.pi * ph) + 0.3)
    fit = fit_item(Item("r", "rotation", 0, 4), loop, 1.5, tolerance=0.005)
    q = fit.evaluate(ph * 1.5)
    assert np.allclose(np.linalg.norm(q, axis=1), 1.0)
    assert rotation_angle(q, loop) <= 0.005 + 1e-12


def test_too_short_loop_is_refused() -> None:
    with pytest.raises(ValueError, match="at least 4"):
        fit_item(Item("a", "scalar", 0, 1), np.zeros((3, 1)), 1.0)


def test_closed_control_is_the_same_curve_on_the_engine_basis() -> None:
    from engine.root_curve import closed_basis

    s = 90
    ph = np.arange(s) / s
    loop = np.stack([np.sin(2 * np.pi * ph), 0.3 * np.cos(4 * np.pi * ph), 0.1 * np.sin(6 * np.pi * ph) ** 3], axis=1)
    fit = fit_item(Item("p", "position", 0, 3), loop, period=1.5, tolerance=0.003)
    c = fit.closed_control()
    assert c.shape == (fit.segments, 3)
    on_engine_basis = closed_basis(s, fit.segments) @ c
    assert np.allclose(on_engine_basis, fit.evaluate(ph * 1.5), atol=1e-12)
