"""The feasible set's compiled line crossings and inside test (:mod:`engine.blend.feasible`) against numpy.

The standing height of every puppet asking for ``height=None`` is a line crossing, and it feeds
the lookup, the pose and the state hashes: both paths must agree bit for bit, and the inside
test must give the same answer, on random points in and around the puppet's feasible set.
"""

from __future__ import annotations

import numpy as np
import pytest

from engine import jit
from engine.blend.puppet import puppet_locomotion

pytestmark = pytest.mark.skipif(not jit.AVAILABLE, reason="numba not installed: only the numpy path exists")


def _points() -> np.ndarray:
    return np.random.default_rng(5).uniform(-0.3, 1.3, (3000, 2))


@pytest.mark.parametrize("axis", [0, 1])
def test_line_crossings_agree_bit_for_bit(axis: int) -> None:
    """Broken once by summing the compiled crossing in plain order (``p₀ + p₁ + p₂``): some crossings
    then differ in the last bit."""
    fs = puppet_locomotion().table.feasible
    assert fs is not None
    x = _points()
    with jit.use(False):
        lo_a, hi_a = fs.line_range(x, axis)
    with jit.use(True):
        lo_b, hi_b = fs.line_range(x, axis)
    assert np.isnan(hi_a).any() and np.isfinite(hi_a).any()  # lines that miss the set and lines that cross it
    assert np.array_equal(lo_a, lo_b, equal_nan=True) and np.array_equal(hi_a, hi_b, equal_nan=True)


def test_inside_test_agrees() -> None:
    """Random points, and points on the border (the top crossings: where a standing puppet's request
    lies), which only the tolerance keeps inside. Broken once by dropping the tolerance from the
    compiled test's barycentric sum (``total <= 1.0``: border points fall out)."""
    fs = puppet_locomotion().table.feasible
    assert fs is not None
    x = _points()
    with jit.use(False):
        _, top = fs.line_range(x, 1)
    border = np.stack([x[:, 0], top], axis=-1)[np.isfinite(top)]
    x = np.concatenate([x, border])
    with jit.use(False):
        a = fs.contains_many(x)
    with jit.use(True):
        b = fs.contains_many(x)
    assert 0 < a.sum() < len(a) and a[-len(border) :].all()
    assert np.array_equal(a, b)
