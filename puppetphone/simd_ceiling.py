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

numpy's matrix products go to OpenBLAS, which also picks its kernels by CPU at load: on an AVX-512
machine (SkylakeX kernels) every shipped recording parted from the AVX2 one (Haswell kernels) at its
first stick update, frame 18 of ``puppet_walk_run.rec``. On an x86-64 CPU with AVX2 and FMA the cap
sets ``OPENBLAS_CORETYPE=Haswell`` (unless the user set it), so OpenBLAS runs those kernels there too;
a CPU without them keeps OpenBLAS's own choice (forcing Haswell kernels on it would be an illegal
instruction).

The cap works only through ``NPY_DISABLE_CPU_FEATURES``, which numpy reads once at import; so
the launcher calls :func:`cap_numpy_dispatch` before anything imports numpy (OpenBLAS reads its
variable when numpy loads it). A program that
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

__all__ = ["ABOVE_CEILING", "BLAS_CORE", "cap_numpy_dispatch"]

#: numpy's dispatch targets above x86-64-v3, as numpy 2.4 names them.
ABOVE_CEILING = ("X86_V4", "AVX512_ICL", "AVX512_SPR")
_VARIABLE = "NPY_DISABLE_CPU_FEATURES"
_NAMED_FROM = (2, 4)  # the numpy release that names its x86 targets X86_V2..V4
#: OpenBLAS's kernels for every x86-64 CPU with AVX2 and FMA (what an AVX2 machine picks itself).
BLAS_CORE = "Haswell"
_BLAS_VARIABLE = "OPENBLAS_CORETYPE"
_BLAS_NEEDS = frozenset({"avx2", "fma"})


def _cpu_flags() -> frozenset[str]:
    """The CPU's feature flags from ``/proc/cpuinfo`` (empty where there is none: not Linux)."""
    try:
        with open("/proc/cpuinfo", encoding="ascii", errors="replace") as info:
            for line in info:
                if line.startswith("flags"):
                    return frozenset(line.partition(":")[2].split())
    except OSError:
        pass
    return frozenset()


def _numpy_names_targets_by_level() -> bool:
    try:
        major, minor = (int(p) for p in version("numpy").split(".")[:2])
    except (PackageNotFoundError, ValueError):
        return False
    return (major, minor) >= _NAMED_FROM


def cap_numpy_dispatch(environ: MutableMapping[str, str] = os.environ, cpu_flags: frozenset[str] | None = None) -> bool:
    """Add :data:`ABOVE_CEILING` to ``NPY_DISABLE_CPU_FEATURES`` (keeping what is there), and set
    ``OPENBLAS_CORETYPE`` to :data:`BLAS_CORE` where the CPU (``cpu_flags``, read from the machine by
    default) has AVX2 and FMA and the user has not set it; ``False`` (nothing changed) when numpy is
    already imported, so the cap would do nothing. numpy older than 2.4 names its targets otherwise:
    its dispatch is left alone."""
    if "numpy" in sys.modules:
        return False
    flags = _cpu_flags() if cpu_flags is None else cpu_flags
    blas = _BLAS_VARIABLE not in environ and _BLAS_NEEDS.issubset(flags)
    if blas:
        environ[_BLAS_VARIABLE] = BLAS_CORE
    if not _numpy_names_targets_by_level():
        return blas
    present = environ.get(_VARIABLE, "").replace(",", " ").split()
    environ[_VARIABLE] = " ".join(present + [f for f in ABOVE_CEILING if f not in present])
    return True
