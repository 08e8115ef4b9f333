"""The lookup's grids of cells (:mod:`engine.blend._grid`) against the k-d trees they replace on the compiled path.

The state hashes see every bit of the blend points, so the nearest probes must be the tree's,
in its order, with its distances, and the inside test must answer what the tree-guided test
answered. Requests inside the feasible set, outside it, far from every probe, on the probes,
on the border within the tolerance and on a lattice where neighbours tie.
"""

from __future__ import annotations

import numpy as np
import pytest

from engine import jit
from engine.blend._grid import BoxGrid, grid_of, knn
from engine.blend.feasible import FeasibleSet, _contains_compiled
from engine.blend.lookup import LookupTable
from engine.blend.puppet import puppet_locomotion

pytestmark = pytest.mark.skipif(not jit.AVAILABLE, reason="numba not installed: the grids serve the compiled path")


@pytest.fixture(scope="module")
def table() -> LookupTable:
    return puppet_locomotion().table


def _knn(grid: object, x: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    dist, idx = np.empty((len(x), k)), np.empty((len(x), k), dtype=np.int64)
    exact = np.empty(len(x), dtype=np.bool_)
    knn(grid.points, grid.lo, grid.size, grid.shape, grid.start, grid.items, x, k, dist, idx, exact)  # type: ignore[attr-defined]  # a PointGrid
    return dist, idx, exact


def _requests(table: LookupTable, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    lo, hi = table._scaled_values.min(axis=0), table._scaled_values.max(axis=0)
    near = lo + rng.random((2000, 2)) * (hi - lo)
    far = lo - 1.5 + rng.random((300, 2)) * (hi - lo + 3.0)
    return np.ascontiguousarray(np.concatenate([near, far, table._scaled_values[::7]]))


@pytest.mark.parametrize("seed", [1, 2])
def test_the_nearest_probes_are_the_trees_bit_for_bit(table: LookupTable, seed: int) -> None:
    """Broken once by stopping the ring search as soon as ``k + 1`` probes are found (no clearance test):
    farther probes than the tree's come back and it fails."""
    assert table._grid is not None
    k = table.neighbours
    x = _requests(table, seed)
    dist, idx, exact = _knn(table._grid, x, k)
    tree_dist, tree_idx = table.tree.query(x, k=k)
    assert exact.all()  # measured probes: no two equally far from these requests
    assert dist.tobytes() == tree_dist.tobytes() and idx.tobytes() == np.asarray(tree_idx, dtype=np.int64).tobytes()
    np.testing.assert_array_equal(table.query_scaled(x), table._idw(x, tree_dist, tree_idx))


def test_tied_neighbours_are_flagged_and_asked_of_the_tree() -> None:
    """On a square lattice the centre of four points has four equally near: the row is flagged and the
    table's answer is the tree's. Broken once by dropping the tie test (every row exact): it fails."""
    probes = np.stack(np.meshgrid(np.linspace(0, 1, 9), np.linspace(0, 1, 9), indexing="ij"), axis=-1).reshape(-1, 2)
    table = LookupTable(probes, probes * [2.0, 0.5], ("speed", "height"), (9, 9), neighbours=4)
    grid = grid_of(table._scaled_values)
    assert grid is not None
    x = np.array([[0.5 / 8, 0.5 / 8], [0.3, 0.71], [0.5, 0.5]])
    dist, idx, exact = _knn(grid, x, 4)
    assert exact.tolist() == [False, True, False]
    tree_dist, tree_idx = table.tree.query(x, k=4)
    np.testing.assert_array_equal(dist[1], tree_dist[1])
    np.testing.assert_array_equal(idx[1], tree_idx[1])
    np.testing.assert_array_equal(table.query_scaled(x), table._idw(x, tree_dist, tree_idx))


@pytest.mark.parametrize("seed", [1, 2])
def test_the_inside_test_on_cells_is_the_tree_guided_test(table: LookupTable, seed: int) -> None:
    """Points inside, outside, far off and within the tolerance of the border (just past the grid's bounds)
    give the tree-guided test's answer, and so do they with cells that guess nothing (the answer does not
    depend on the guesses). Broken once by dropping the scan of every simplex after the cell's: it fails."""
    fs = table.feasible
    assert fs is not None and fs._cells is not None
    rng = np.random.default_rng(seed)
    x = _requests(table, seed)
    border = fs.values[np.unique(fs.border)]
    hairline = np.clip(border, 0.0, 1.0) + np.sign(border - 0.5) * 1e-9  # past the bounds, within tolerance
    x = np.ascontiguousarray(np.concatenate([x, hairline, border + rng.normal(scale=1e-3, size=border.shape)]))
    _, near = fs._centroids.query(x, k=min(12, len(fs.simplices)))
    expected = np.empty(len(x), dtype=np.bool_)
    _contains_compiled(fs.values, fs.simplices, fs._inv, fs._valid, near, x, 1e-6, expected)
    got = fs.contains_compiled(x, 1e-6)
    np.testing.assert_array_equal(got, expected)
    assert expected.any() and not expected.all()
    assert expected[2300 + len(table._scaled_values[::7]) :][: len(hairline)].any()  # some hairline points inside
    blind = FeasibleSet(fs.grid_shape, fs.values)
    cells = blind._cells
    assert cells is not None
    no_guess = BoxGrid(cells.lo, cells.size, cells.shape, np.zeros_like(cells.start), cells.items[:0])
    object.__setattr__(blind, "_cells", no_guess)
    np.testing.assert_array_equal(blind.contains_compiled(x, 1e-6), expected)
