"""The curve descriptor: the paper's formula, and the three exact ways of computing its rows."""

from __future__ import annotations

import numpy as np
import pytest

from authoring.cycles.descriptor import Descriptor, central_difference


def _brute_force(t: np.ndarray, v: np.ndarray, k_max: int) -> np.ndarray:
    """The paper's definition written out literally: stacked h and g, full distance matrix."""
    n = len(t)
    d1 = central_difference(t, v)
    d2 = central_difference(t, d1)

    def stack(d: np.ndarray) -> np.ndarray:
        cols = []
        for k in range(k_max + 1):
            cols.append(np.array([sum(d[min(max(j, 0), n - 1)] for j in range(i - k, i + k + 1)) for i in range(n)]))
        return np.concatenate(cols, axis=1)

    h, g = stack(d1), stack(d2)
    dh = np.linalg.norm(h[:, None] - h[None], axis=2)
    dg = np.linalg.norm(g[:, None] - g[None], axis=2)
    return dh * dg


@pytest.fixture
def curve() -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(3)
    t = np.cumsum(rng.uniform(0.5, 1.5, 80)) / 60.0  # uneven sampling
    v = np.stack([np.sin(2 * np.pi * t), np.cos(4 * np.pi * t) + 0.1 * t, rng.normal(size=80) * 0.01], axis=1)
    return t, v


@pytest.mark.parametrize("strategy", ["stacked", "gram", "stream"])
def test_rows_match_the_literal_definition(curve: tuple[np.ndarray, np.ndarray], strategy: str) -> None:
    t, v = curve
    full = _brute_force(t, v, 5)
    q = np.array([0, 7, 40, 79])
    rows = Descriptor(t, v, 5, strategy=strategy).rows(q)
    assert np.allclose(rows, full[q], rtol=1e-7, atol=1e-9 * full.max())


def test_central_difference_handles_uneven_times() -> None:
    t = np.array([0.0, 0.1, 0.3, 0.6])
    v = (3.0 * t)[:, None]
    assert np.allclose(central_difference(t, v), 3.0)


def test_descriptor_ignores_offsets_and_finds_the_repeat() -> None:
    t = np.arange(300) / 60.0
    v = (np.sin(2 * np.pi * t) + 0.5 * np.sin(4 * np.pi * t + 0.7))[:, None] + 5.0  # period 60 samples
    row = Descriptor(t, v).rows([20])[0]
    assert row[20] == 0.0
    # The most similar other points are one period away, not half or a quarter of one.
    assert row[80] < 1e-3 * row.max() and row[140] < 1e-3 * row.max()
    assert row[50] > 0.05 * row.max() and row[35] > 0.05 * row.max()


def test_bad_queries_raise() -> None:
    d = Descriptor(np.arange(10.0), np.zeros((10, 1)))
    with pytest.raises(IndexError):
        d.rows([10])
    with pytest.raises(ValueError, match="strategy"):
        Descriptor(np.arange(10.0), np.zeros((10, 1)), strategy="magic")
