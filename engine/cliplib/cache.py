"""Derived data cached on disk by a content hash: the lookup table's measurement, the built-in clips.

Measuring the puppet's table plays 961 blends for a cycle each (about half a second,
more with long mocap cycles); a set of authored clips is measured once and the result
kept in ``$XDG_CACHE_HOME/puppetphone/lookup/<key>.npz``, so the next start with the
same clips skips it. The key covers everything the numbers depend on: the clips'
content hash, the probe grid and step, the source of the modules that play and
measure a blend, the numpy version and the kernels it runs on this CPU (the SIMD targets and
OpenBLAS core the launcher holds it at, :mod:`puppetphone.simd_ceiling`: a table measured before
those caps, on an AVX-512 machine's kernels, parted every crowd's state from the capped one's) —
a cache written by other code is never read,
since a replay must measure exactly what the recorded session measured. Each file
carries the SHA-256 of its key, probes and values; a cache file that is unreadable, does
not match its probes or its checksum (damaged, or edited by hand) is ignored and
rewritten (it is a cache: losing it costs half a second, never a wrong answer).

:func:`read_checked` / :func:`write_checked` are that file discipline on their own (a
SHA-256 over the key and every array, an atomic write, any failure a miss): the built-in
clips (:mod:`engine.clips.stored`) are kept with them too.
"""

from __future__ import annotations

import hashlib
import io
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from engine.arrays import F64 as F
from engine.atomic import atomic_write_bytes
from engine.npz_safe import read_bounded, read_npz

__all__ = [
    "FILE_FORMAT",
    "MeasureCache",
    "cache_root",
    "code_fingerprint",
    "kernel_choice",
    "default_cache_dir",
    "read_checked",
    "write_checked",
]

_ENGINE = Path(__file__).resolve().parents[1]
_MEASURING = (
    "blend/measure.py",
    "blend/space.py",
    "blend/sync.py",
    "blend/pose_blend.py",
    "clip.py",
    "quat.py",
    "fk.py",
)


def cache_root() -> Path:
    """``$XDG_CACHE_HOME/puppetphone`` (``~/.cache/puppetphone`` when unset or empty)."""
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "puppetphone"


def default_cache_dir() -> Path:
    """``$XDG_CACHE_HOME/puppetphone/lookup`` (``~/.cache/puppetphone/lookup`` when unset)."""
    return cache_root() / "lookup"


_SHA = "sha256"  # the member of a cache file that holds its checksum
_KERNEL_CHOICE = ("NPY_DISABLE_CPU_FEATURES", "OPENBLAS_CORETYPE")  # read when numpy loads: its kernels
#: Part of every key: a build that lays files out otherwise never reads (nor fights over) these.
FILE_FORMAT = "puppetphone-cache/2"


def _entry_digest(key: str, arrays: dict[str, NDArray[Any]]) -> bytes:
    """A cache file's checksum: its key, then every array's name, dtype, shape and bytes, by name."""
    h = hashlib.sha256(key.encode())
    for name in sorted(arrays):
        a = np.ascontiguousarray(arrays[name])
        h.update(f"\0{name}\0{a.dtype.str}\0{a.shape}\0".encode() + a.tobytes())
    return h.digest()


def read_checked(path: Path, key: str, limit: int = 64 << 20) -> dict[str, NDArray[Any]] | None:
    """The arrays :func:`write_checked` stored at ``path`` under ``key``; ``None`` (a miss) when the
    file is missing, unreadable, larger than ``limit``, damaged, or was written under another key."""
    try:
        arrays = read_npz(read_bounded(path, limit))
    except (OSError, ValueError):  # NpzError is a ValueError
        return None
    digest = arrays.pop(_SHA, None)
    if digest is None or digest.dtype != np.uint8 or digest.tobytes() != _entry_digest(key, arrays):
        return None
    return arrays


def write_checked(path: Path, key: str, arrays: dict[str, NDArray[Any]]) -> bool:
    """Store ``arrays`` at ``path`` atomically with their checksum under ``key``; ``False`` when it
    could not be written (a read-only or full cache folder only costs the next start the rebuild)."""
    if _SHA in arrays:
        raise ValueError(f"{_SHA!r} is the checksum's member; name the array otherwise")
    buf = io.BytesIO()
    members: dict[str, Any] = {**arrays, _SHA: np.frombuffer(_entry_digest(key, arrays), dtype=np.uint8)}
    np.savez(buf, **members)  # (typed Any: numpy's stub reads ** as its keyword options)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        atomic_write_bytes(path, buf.getvalue())
    except OSError:
        return False
    return True


def kernel_choice() -> str:
    """The variables that chose numpy's and OpenBLAS's kernels when numpy loaded, as text for a cache key:
    the same code and versions on other kernels round otherwise (see the module docstring)."""
    return "".join(f"{variable}={os.environ.get(variable, '')};" for variable in _KERNEL_CHOICE)


def code_fingerprint() -> str:
    """Hash of the code that measures a blend, numpy's version and the kernels it was held at (see the
    module docstring)."""
    h = hashlib.sha256(np.__version__.encode() + kernel_choice().encode())
    for rel in _MEASURING:
        h.update(rel.encode() + (_ENGINE / rel).read_bytes())
    return h.hexdigest()


class MeasureCache:
    """A ``memo`` for :func:`engine.blend.puppet.build_locomotion`: measured values by key in ``folder``.

    Attributes:
        hits / misses: how often this cache answered or had to measure (for the launcher's report).
    """

    def __init__(self, folder: str | Path, key: str) -> None:
        self.folder = Path(folder)
        self.key = hashlib.sha256((FILE_FORMAT + key + code_fingerprint()).encode()).hexdigest()[:32]
        self.hits = 0
        self.misses = 0

    @property
    def path(self) -> Path:
        return self.folder / f"{self.key}.npz"

    def _read(self, probes: F) -> F | None:
        arrays = read_checked(self.path, self.key)
        if arrays is None:
            return None
        got, values = arrays.get("probes"), arrays.get("values")
        if got is None or values is None or got.shape != probes.shape or not np.array_equal(got, probes):
            return None
        if values.dtype != np.float64 or values.shape[0] != len(probes) or not np.isfinite(values).all():
            return None
        return values

    def __call__(self, probes: F, measure: Callable[[F], F]) -> F:
        cached = self._read(probes)
        if cached is not None:
            self.hits += 1
            return cached
        self.misses += 1
        values = np.asarray(measure(probes), dtype=np.float64)
        write_checked(self.path, self.key, {"probes": np.asarray(probes, dtype=np.float64), "values": values})
        return values
