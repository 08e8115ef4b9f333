"""Validated performances: shapes, NaN, times, items and quaternion continuity."""

from __future__ import annotations

import numpy as np
import pytest

from authoring.cycles.trajectory import Item, Trajectory, TrajectoryError, continuous_quaternions
from engine import quat


def test_default_items_one_scalar_per_column() -> None:
    tr = Trajectory.uniform(np.zeros((10, 3)), 30.0)
    assert [it.kind for it in tr.items] == ["scalar"] * 3
    assert tr.dims == 3 and tr.num_samples == 10
    assert tr.dt == pytest.approx(1 / 30)


@pytest.mark.parametrize(
    ("times", "values", "message"),
    [
        (np.arange(5.0), np.zeros((4, 2)), "values must be"),
        (np.array([0.0, 1.0, 1.0, 2.0]), np.zeros((4, 1)), "increase strictly"),
        (np.arange(4.0), np.array([[0.0], [np.nan], [1.0], [2.0]]), "NaN"),
        (np.arange(4.0), np.zeros((4, 0)), "no dimensions"),
    ],
)
def test_bad_input_is_refused_clearly(times: np.ndarray, values: np.ndarray, message: str) -> None:
    with pytest.raises(TrajectoryError, match=message):
        Trajectory(times, values)


def test_items_are_checked() -> None:
    with pytest.raises(TrajectoryError, match="4 quaternion columns"):
        Item("q", "rotation", 0, 3)
    with pytest.raises(TrajectoryError, match="kind"):
        Item("x", "colour", 0, 1)
    with pytest.raises(TrajectoryError, match="more than one item"):
        Trajectory(np.arange(3.0), np.zeros((3, 2)), (Item("a", "scalar", 0, 2), Item("b", "scalar", 1, 2)))
    with pytest.raises(TrajectoryError, match="reaches column"):
        Trajectory(np.arange(3.0), np.zeros((3, 2)), (Item("a", "position", 0, 3),))


def test_quaternion_signs_are_made_continuous() -> None:
    angles = np.linspace(0, 1.5, 20)
    q = quat.from_axis_angle(np.array([0.0, 1.0, 0.0]), angles)
    flipped = q.copy()
    flipped[::3] *= -1.0
    out = continuous_quaternions(flipped)
    assert np.all(np.einsum("ij,ij->i", out[1:], out[:-1]) > 0)
    assert np.allclose(out, q) or np.allclose(out, -q)  # one global sign, chosen by the first sample
    tr = Trajectory.uniform(flipped * 2.0, 30.0, [Item("r", "rotation", 0, 4)])
    assert np.allclose(np.linalg.norm(tr.values, axis=1), 1.0)


def test_weights_balance_units_between_kinds() -> None:
    t = np.arange(200) / 60
    pos = np.stack([100 * np.sin(t), 100 * np.cos(t), 0 * t], axis=1)  # centimetres
    rot = quat.from_axis_angle(np.array([1.0, 0, 0]), 0.3 * np.sin(t))
    tr = Trajectory(t, np.concatenate([pos, rot], axis=1), (Item("p", "position", 0, 3), Item("r", "rotation", 3, 7)))
    w = tr.weights()
    speed = np.diff(tr.values * w, axis=0) / np.diff(t)[:, None]
    rms_p = np.sqrt(np.mean(speed[:, :3] ** 2))
    rms_r = np.sqrt(np.mean(speed[:, 3:] ** 2))
    assert rms_p == pytest.approx(rms_r, rel=1e-9)
