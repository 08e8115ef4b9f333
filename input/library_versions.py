"""The versions of the libraries that change the numbers, as a recording's header keeps them.

A recording replays bit for bit only with the same numerical libraries (constraints.txt pins
them: a new mujoco moves frame 0 of most shipped recordings). So every recording's header
stores the versions it was made with (``libraries``), and ``replay`` says in one line when the
running ones differ ("recorded with mujoco 4.0.0, running 3.17.0: hashes may differ"), before
a hash mismatch leaves the person guessing. Recordings made before the header had them
(the shipped ones among them) carry none, and are replayed without the line.

Beside the versions, the same map keeps what the CPU makes of them: the machine (``x86_64``,
``aarch64``: another instruction set runs other code) and ``numpy-simd``, the widest SIMD
target numpy's kernels dispatch to here (``X86_V3`` is AVX2; the launcher caps it there,
:mod:`puppetphone.simd_ceiling`, since the AVX-512 kernels round differently).
"""

from __future__ import annotations

import importlib
import platform
from functools import lru_cache

__all__ = ["NUMERIC_LIBRARIES", "libraries_problem", "numpy_simd_level", "running_versions", "version_difference"]

#: The distributions whose version can change a state hash: exactly the ones constraints.txt pins.
NUMERIC_LIBRARIES = (
    "numpy",
    "scipy",
    "mujoco",
    "mujoco-core",
    "mujoco-studio",
    "osqp",
    "daqp",
    "cma",
    "opencv-python-headless",
    "pillow",
    "numba",  # the crowd's compiled kernels round their sums their own way
    "llvmlite",
)
_MAX_NAME = 64


@lru_cache(maxsize=1)
def _versions() -> tuple[tuple[str, str], ...]:
    from importlib.metadata import PackageNotFoundError, version

    found = []
    for name in NUMERIC_LIBRARIES:
        try:
            found.append((name, version(name)))
        except PackageNotFoundError:
            found.append((name, "none"))  # not installed: recorded as such, so a later install is noticed
    found.append(("numpy-simd", numpy_simd_level()))
    found.append(("machine", platform.machine() or "unknown"))
    return tuple(found)


def numpy_simd_level() -> str:
    """The widest SIMD target numpy dispatches to in this process ("X86_V3", "AVX512_SKX", …, or "baseline")."""
    for where in ("numpy._core._multiarray_umath", "numpy.core._multiarray_umath"):  # numpy 2, numpy 1
        try:
            umath = importlib.import_module(where)
        except ImportError:
            continue
        break
    else:
        return "unknown"
    features, targets = umath.__cpu_features__, umath.__cpu_dispatch__
    enabled = [t for t in targets if features.get(t)]
    return enabled[-1] if enabled else "baseline"


def running_versions() -> dict[str, str]:
    """``{distribution: version}`` of :data:`NUMERIC_LIBRARIES` in this process ("none" when absent),
    with ``numpy-simd`` and ``machine`` (see the module docstring)."""
    return dict(_versions())


def libraries_problem(value: object) -> str:
    """What is wrong with a header's ``libraries`` (``""`` if nothing): a short map of names to versions."""
    if not isinstance(value, dict) or len(value) > 4 * len(NUMERIC_LIBRARIES):
        return f"libraries must be an object of at most {4 * len(NUMERIC_LIBRARIES)} names and versions"
    for name, ver in value.items():
        if not (isinstance(ver, str) and 0 < len(name) <= _MAX_NAME and 0 < len(ver) <= _MAX_NAME):
            return f"libraries must map names to version strings of 1..{_MAX_NAME} characters"
    return ""


def version_difference(recorded: dict[str, str], running: dict[str, str] | None = None) -> str:
    """One line when ``recorded`` differs from the running versions, else ``""`` (also for no versions).

    Only libraries the recording names are compared: one made before a library was added
    to the list says nothing about it.
    """
    now = running_versions() if running is None else running
    differ = [(name, was, now.get(name, "none")) for name, was in recorded.items() if now.get(name, "none") != was]
    if not differ:
        return ""
    then = ", ".join(f"{name} {was}" for name, was, _ in differ)
    if len(differ) == 1:
        return f"recorded with {then}, running {differ[0][2]}: hashes may differ"
    return f"recorded with {then}; running {', '.join(f'{name} {is_}' for name, _, is_ in differ)}: hashes may differ"
