"""Stitching closes the loop exactly, for vectors and on the quaternion sphere."""

from __future__ import annotations

import numpy as np
import pytest

from authoring.cycles.stitch import closure_error, rotation_angle, stitch
from authoring.cycles.trajectory import Item, Trajectory
from engine import quat


def _traj(n_cols: int, items: tuple[Item, ...]) -> Trajectory:
    return Trajectory(np.arange(3.0), np.tile(np.array([1.0, 0, 0, 0] + [0.0] * (n_cols - 4))[None], (3, 1)), items)


def test_vector_stitch_is_the_paper_formula() -> None:
    tr = Trajectory(np.arange(3.0), np.zeros((3, 2)))
    phases = np.linspace(0, 1, 11)
    curve = np.stack([phases * 2.0, np.sin(phases * 3)], axis=1)
    out, gap = stitch(tr, curve, phases, np.zeros(2))
    d_ex = curve[0] - curve[-1]
    assert np.allclose(gap, d_ex)
    assert np.allclose(out, curve + (phases - 0.5)[:, None] * d_ex)
    assert np.allclose(out[0], out[-1], atol=1e-15)
    assert closure_error(tr, out, np.zeros(2)) < 1e-14


def test_travel_is_kept() -> None:
    tr = Trajectory(np.arange(3.0), np.zeros((3, 3)), (Item("root", "position", 0, 3, travel=True),))
    phases = np.linspace(0, 1, 21)
    curve = np.stack(
        [phases * 1.3 + 0.05 * np.sin(9 * phases), 0.1 * np.cos(2 * np.pi * phases) + 0.02, 0 * phases], axis=1
    )
    travel = np.array([1.3, 0.0, 0.0])
    out, _ = stitch(tr, curve, phases, travel)
    assert np.allclose(out[-1] - out[0], travel, atol=1e-14)
    assert closure_error(tr, out, travel) < 1e-14


def test_quaternion_stitch_stays_on_the_sphere_and_closes() -> None:
    tr = _traj(4, (Item("r", "rotation", 0, 4),))
    phases = np.linspace(0, 1, 31)
    axis = np.array([0.3, 1.0, 0.2])
    curve = quat.from_axis_angle(axis, 2.0 * np.sin(2 * np.pi * phases) + 0.4 * phases)  # opens by 0.4 rad
    out, gap = stitch(tr, curve, phases, np.zeros(4))
    assert np.allclose(np.linalg.norm(out, axis=1), 1.0)
    assert rotation_angle(out[0], out[-1]) < 1e-12
    assert np.linalg.norm(gap[:3]) == pytest.approx(0.4, rel=1e-9)
    # Each sample moves by at most half the gap, linearly in phase.
    moved = [rotation_angle(a, b) for a, b in zip(out, curve, strict=True)]
    assert max(moved) == pytest.approx(0.2, rel=1e-6)
    assert closure_error(tr, out, np.zeros(4)) < 1e-12


def test_rotation_angle_is_accurate_near_zero() -> None:
    a = quat.from_axis_angle(np.array([0, 0, 1.0]), 0.3)
    b = quat.from_axis_angle(np.array([0, 0, 1.0]), 0.3 + 1e-9)
    assert rotation_angle(a, b) == pytest.approx(1e-9, rel=1e-4)
