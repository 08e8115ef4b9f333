"""engine.jit defers numba: a process that runs no kernel never imports it; a deferred kernel calls,
and is called by, compiled kernels as numba's own dispatcher would.

Broken on purpose to see these fail: ``import numba`` back at the top of engine/jit.py (the first test
finds numba loaded before any kernel ran); ``_Kernel.__getattr__`` not forwarding to the dispatcher (the
second test: numba can neither type nor inline the deferred helpers inside the kernel that calls them).
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from engine import jit

ROOT = Path(__file__).resolve().parents[2]

_PROBE = """
import sys
import numpy as np
import engine.fk as fk, engine.blend._kernel, engine.ik._ground_kernel  # kernels defined, none run
print("before", "numba" in sys.modules, type(fk.fk_kernel).__name__)
parents = np.array([-1, 0], dtype=np.int64)
out_pos, out_rot = np.zeros((1, 2, 3)), np.zeros((1, 2, 4))
fk.fk_kernel(parents, np.zeros((1, 3)), np.tile([1.0, 0, 0, 0], (1, 2, 1)), np.ones((1, 2, 3)), out_pos, out_rot)
print("after", "numba" in sys.modules, type(fk.fk_kernel).__name__, out_pos[0, 1].tolist())
"""


@pytest.mark.skipif(not jit.AVAILABLE, reason="numba not installed: there are no compiled kernels")
def test_numba_loads_with_the_first_kernel_run_not_with_the_engine() -> None:
    done = subprocess.run(
        [sys.executable, "-c", _PROBE], cwd=ROOT, capture_output=True, text=True, check=True, timeout=300
    )
    before, after = done.stdout.splitlines()[-2:]
    assert before == "before False _Kernel"
    # the kernel ran compiled, and its module now names numba's dispatcher itself
    assert after == "after True CPUDispatcher [1.0, 1.0, 1.0]"


def _twice(x: float) -> float:
    return 2.0 * x


def _plus_one(x: float) -> float:
    return x + 1.0


@pytest.mark.skipif(not jit.AVAILABLE, reason="numba not installed: there are no compiled kernels")
def test_a_deferred_kernel_is_called_and_inlined_inside_a_compiled_one() -> None:
    twice = jit._Kernel(_twice, {"nogil": True, "error_model": "numpy"})
    inlined = jit._Kernel(_plus_one, {"nogil": True, "error_model": "numpy", "inline": "always"})

    def outer(x: float) -> float:
        return twice(x) + inlined(x)  # both globals of this kernel are deferred ones

    compiled = jit._numba().njit(outer)
    assert compiled(3.0) == 10.0
    assert twice(4.0) == 8.0 and twice.py_func is _twice  # a dispatcher's attributes, through the stand-in
    (llvm,) = compiled.inspect_llvm().values()
    assert "_plus_one" not in llvm and "_twice" in llvm  # the inline helper was inlined, the other called


def _cube(x: float) -> float:
    return x * x * x


@pytest.mark.skipif(not jit.AVAILABLE, reason="numba not installed: there are no compiled kernels")
def test_compile_seconds_count_a_kernels_compile_once_and_not_its_calls() -> None:
    """The window's time keeper leaves compiles out of its verdict: they must be counted when a kernel
    compiles (an uncached one here), and not again when it runs."""
    cube = jit._Kernel(_cube, {"nogil": True, "error_model": "numpy"})  # not cached: it always compiles
    before = jit.compile_seconds()
    assert cube(2.0) == 8.0
    compiled = jit.compile_seconds()
    assert compiled > before
    assert cube(3.0) == 27.0 and jit.compile_seconds() == compiled
