"""Cap numpy's CPU dispatch at x86-64-v3 (AVX2) before numpy loads, so replays agree across CPUs.

numpy picks, at import, the widest SIMD kernels the CPU runs. For float64 ``sin``, ``cos``,
``exp``, ``log``, ``tanh`` it has x86-64-v3 (AVX2) kernels and, beside them, x86-64-v4
(AVX-512) ones; for ``arccos``, ``arctan2`` and ``power`` only AVX-512 kernels besides the C
library's. Those kernels round differently in the last bit, and one bit is enough for a
replay's state hash to part at the first ragdoll: a recording made on an AVX2 machine would
not verify on an AVX-512 one. Disabling the AVX-512 targets makes every x86-64 machine with
AVX2 run the same machine code for these functions (replaying the shipped recordings with
numpy held at its x86-64-v2 baseline and numba compiling for a generic x86-64 gives the same
hashes here as well, so older CPUs agree too; ``tests/puppetphone/test_simd_ceiling.py``).

The cap works only through ``NPY_DISABLE_CPU_FEATURES``, which numpy reads once at import; so
the launcher calls :func:`cap_numpy_dispatch` before anything imports numpy. A program that
imported numpy first keeps its kernels (the recording header names them: ``numpy-simd``).
The target names are numpy 2.4's, and numpy warns at import about a name it does not
dispatch, so older numpy (the floor environment) is left alone: replays are promised only
with constraints.txt's versions anyway. This module must not import numpy.
"""

from __future__ import annotations

import os
import sys
from collections.abc import MutableMapping
from importlib.metadata import PackageNotFoundError, version

__all__ = ["ABOVE_CEILING", "cap_numpy_dispatch"]

#: numpy's dispatch targets above x86-64-v3, as numpy 2.4 names them.
ABOVE_CEILING = ("X86_V4", "AVX512_ICL", "AVX512_SPR")
_VARIABLE = "NPY_DISABLE_CPU_FEATURES"
_NAMED_FROM = (2, 4)  # the numpy release that names its x86 targets X86_V2..V4


def _numpy_names_targets_by_level() -> bool:
    try:
        major, minor = (int(p) for p in version("numpy").split(".")[:2])
    except (PackageNotFoundError, ValueError):
        return False
    return (major, minor) >= _NAMED_FROM


def cap_numpy_dispatch(environ: MutableMapping[str, str] = os.environ) -> bool:
    """Add :data:`ABOVE_CEILING` to ``NPY_DISABLE_CPU_FEATURES`` (keeping what is there);
    ``False`` (nothing changed) when numpy is already imported, so the cap would do nothing, or
    is older than 2.4 and names its targets otherwise."""
    if "numpy" in sys.modules or not _numpy_names_targets_by_level():
        return False
    present = environ.get(_VARIABLE, "").replace(",", " ").split()
    environ[_VARIABLE] = " ".join(present + [f for f in ABOVE_CEILING if f not in present])
    return True
