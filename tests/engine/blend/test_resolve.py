"""One compiled resolve of the changed requests (:mod:`engine.blend._resolve`) against the set's methods.

The state hashes see every bit of the blend points, so the fused pass (standing heights,
scaling, inside test, IDW) must answer exactly what ``standing_heights`` then ``resolve_many``
answer with numba (:func:`stepwise`, what the stage ran before), on random crowds: feasible requests, requests too fast or too low (projected), standing
ones (slow, fast, beyond the fastest blend) and requests on the probes themselves.
"""

from __future__ import annotations

import numpy as np
import pytest

from engine import jit
from engine.blend._resolve import resolve_rows, stepwise
from engine.blend.locomotion import LocomotionSet
from engine.blend.puppet import puppet_locomotion

pytestmark = pytest.mark.skipif(not jit.AVAILABLE, reason="numba not installed: only the numpy path exists")


@pytest.fixture(scope="module")
def loco() -> LocomotionSet:
    return puppet_locomotion()


def _requests(loco: LocomotionSet, n: int, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    values = loco.table.values
    speeds = rng.uniform(0.0, values[:, 0].max() * 1.4, n)
    heights = rng.uniform(values[:, 1].min() * 0.8, values[:, 1].max() * 1.05, n)
    standing = rng.random(n) < 0.4
    heights[standing] = 0.0  # what the stage stores for a standing row
    speeds[:5], heights[:5], standing[:5] = values[:5, 0], values[:5, 1], False  # on the probes
    return speeds, heights, standing


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_the_compiled_resolve_is_the_stepwise_resolve_bit_for_bit(loco: LocomotionSet, seed: int) -> None:
    """Broken once by scaling the requests' heights as ``(h − offset)·(1/scale)`` (the same number but for
    the last bits): it failed."""
    speeds, heights, standing = _requests(loco, 300, seed)
    with jit.use(True):
        compiled = resolve_rows(loco, speeds, heights, standing)
        reference = stepwise(loco, speeds, heights, standing)
    assert (~compiled[2]).sum() > 10 and compiled[2].sum() > 10  # both kinds of rows were tried
    for a, b in zip(compiled, reference, strict=True):
        assert a.dtype == b.dtype and np.array_equal(a, b)


def test_without_numba_the_path_is_stepwise_and_agrees_closely(loco: LocomotionSet) -> None:
    """The numpy path (its own IDW and inside test) answers the same flags and rates, points to 1e-12."""
    speeds, heights, standing = _requests(loco, 200, 5)
    with jit.use(True):
        compiled = resolve_rows(loco, speeds, heights, standing)
    with jit.use(False):
        numpy = resolve_rows(loco, speeds, heights, standing)
    assert np.array_equal(compiled[2], numpy[2]) and np.array_equal(compiled[3], numpy[3])
    np.testing.assert_allclose(compiled[0], numpy[0], atol=1e-12)
    np.testing.assert_allclose(compiled[1], numpy[1], atol=1e-12)


def test_a_request_that_is_not_finite_fails_clearly(loco: LocomotionSet) -> None:
    speeds, heights, standing = _requests(loco, 8, 4)
    heights[3], standing[3] = np.inf, False
    with jit.use(True), pytest.raises(ValueError, match="NaN or infinite"):
        resolve_rows(loco, speeds, heights, standing)
