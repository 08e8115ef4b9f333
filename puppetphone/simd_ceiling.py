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
variable when numpy loads it). A program that imported numpy first keeps its kernels (the
recording header names them: ``numpy-simd``). numpy 2.4 names its targets by level; 1.26 to 2.3
(the floor environment's 1.26 among them) by instruction set, and warn at import about a name they
do not dispatch, so each gets its own list. Replays are promised only with constraints.txt's
versions, but the compiled kernels' tests compare them with numpy bit for bit under every release
(the floor's AVX-512 ``arccos`` parted a slerp from numba's in the last bit). This module must not
import numpy.
"""

from __future__ import annotations

import os
import sys
from collections.abc import MutableMapping
from importlib.metadata import PackageNotFoundError, version

__all__ = ["ABOVE_CEILING", "BLAS_CORE", "cap_numpy_dispatch"]

#: numpy's dispatch targets above x86-64-v3, as numpy 2.4 names them.
ABOVE_CEILING = ("X86_V4", "AVX512_ICL", "AVX512_SPR")
#: The same before 2.4, named by instruction set: 1.26 to 2.2 dispatch up to Ice Lake, 2.3 adds Sapphire
#: Rapids. A name the release does not dispatch makes numpy warn at import (an error under ``-W error``).
_AVX512_BY_SET = (
    "AVX512F",
    "AVX512CD",
    "AVX512_KNL",
    "AVX512_KNM",
    "AVX512_SKX",
    "AVX512_CLX",
    "AVX512_CNL",
    "AVX512_ICL",
)
_VARIABLE = "NPY_DISABLE_CPU_FEATURES"
_NAMED_FROM = (2, 4)  # the numpy release that names its x86 targets X86_V2..V4 (ABOVE_CEILING)
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


def _targets_above_ceiling() -> tuple[str, ...]:
    """The installed numpy's dispatch targets above x86-64-v3 (none for a release older than 1.26, or none
    installed: its dispatch is left alone)."""
    try:
        release = tuple(int(p) for p in version("numpy").split(".")[:2])
    except (PackageNotFoundError, ValueError):
        return ()
    if release >= _NAMED_FROM:
        return ABOVE_CEILING
    if release >= (2, 3):
        return (*_AVX512_BY_SET, "AVX512_SPR")
    return _AVX512_BY_SET if release >= (1, 26) else ()


def cap_numpy_dispatch(environ: MutableMapping[str, str] = os.environ, cpu_flags: frozenset[str] | None = None) -> bool:
    """Add :data:`ABOVE_CEILING` to ``NPY_DISABLE_CPU_FEATURES`` (keeping what is there), and set
    ``OPENBLAS_CORETYPE`` to :data:`BLAS_CORE` where the CPU (``cpu_flags``, read from the machine by
    default) has AVX2 and FMA and the user has not set it; ``False`` (nothing changed) when numpy is
    already imported, so the cap would do nothing."""
    if "numpy" in sys.modules:
        return False
    blas = _BLAS_VARIABLE not in environ and _BLAS_NEEDS.issubset(_cpu_flags() if cpu_flags is None else cpu_flags)
    if blas:
        environ[_BLAS_VARIABLE] = BLAS_CORE
    targets = _targets_above_ceiling()
    if not targets:
        return blas
    present = environ.get(_VARIABLE, "").replace(",", " ").split()
    environ[_VARIABLE] = " ".join(present + [f for f in targets if f not in present])
    return True
