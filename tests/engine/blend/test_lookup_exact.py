"""A request that lands exactly on a probe answers that probe, clamped to the blend space like any answer.

Probes are not checked to lie in ``[0, 1]`` (a caller may pass its own), so the exact-hit shortcut
clamps as the weighted answer does. Shown to fail by mutation (docs/mutation.md, fifth round): the
compiled kernel's exact-hit clamp ``min(…, 1.0)`` made ``min(…, 2.0)`` (mutated with the kernel's
``@jit.njit`` taken off in the scratch copy). Both paths are run: numba's and numpy's.
"""

from __future__ import annotations

import numpy as np
import pytest

from engine import jit
from engine.blend.lookup import LookupTable

PATHS = [False, True] if jit.AVAILABLE else [False]


@pytest.mark.parametrize("compiled", PATHS)
@pytest.mark.parametrize("gradients", [False, True])
def test_a_probe_hit_exactly_is_clamped_to_the_blend_space(compiled: bool, gradients: bool) -> None:
    probes = np.array([[-0.5], [0.5], [1.5]])
    values = np.array([[0.0], [1.0], [2.0]])
    table = LookupTable(probes, values, ("speed",), (3,), power=2.0, gradients=gradients)
    with jit.use(compiled):
        got = table.query(np.array([[0.0], [1.0], [2.0]]))
    np.testing.assert_array_equal(got, [[0.0], [0.5], [1.0]])
