"""The lookup table's measurement, cached on disk by the clips' content hash.

Measuring the puppet's table plays 961 blends for a cycle each (about half a second,
more with long mocap cycles); a set of authored clips is measured once and the result
kept in ``$XDG_CACHE_HOME/puppetphone/lookup/<key>.npz``, so the next start with the
same clips skips it. The key covers everything the numbers depend on: the clips'
content hash, the probe grid and step, the source of the modules that play and
measure a blend, and the numpy version — a cache written by other code is never read,
since a replay must measure exactly what the recorded session measured. Each file
carries the SHA-256 of its key, probes and values; a cache file that is unreadable, does
not match its probes or its checksum (damaged, or edited by hand) is ignored and
rewritten (it is a cache: losing it costs half a second, never a wrong answer).
"""

from __future__ import annotations

import hashlib
import io
import os
from collections.abc import Callable
from pathlib import Path

import numpy as np

from engine.arrays import F64 as F
from engine.atomic import atomic_write_bytes
from engine.npz_safe import read_bounded, read_npz

__all__ = ["MeasureCache", "default_cache_dir", "code_fingerprint"]

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


def default_cache_dir() -> Path:
    """``$XDG_CACHE_HOME/puppetphone/lookup`` (``~/.cache/puppetphone/lookup`` when unset)."""
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "puppetphone" / "lookup"


def code_fingerprint() -> str:
    """Hash of the code that measures a blend, and numpy's version (see the module docstring)."""
    h = hashlib.sha256(np.__version__.encode())
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
        self.key = hashlib.sha256((key + code_fingerprint()).encode()).hexdigest()[:32]
        self.hits = 0
        self.misses = 0

    @property
    def path(self) -> Path:
        return self.folder / f"{self.key}.npz"

    def _read(self, probes: F) -> F | None:
        try:
            arrays = read_npz(read_bounded(self.path, 64 << 20))
        except (OSError, ValueError):
            return None
        got, values = arrays.get("probes"), arrays.get("values")
        if got is None or values is None or got.shape != probes.shape or not np.array_equal(got, probes):
            return None
        if values.dtype != np.float64 or values.shape[0] != len(probes) or not np.isfinite(values).all():
            return None
        digest = arrays.get("sha256")
        if digest is None or digest.dtype != np.uint8 or digest.tobytes() != self._digest(got, values):
            return None
        return values

    def _digest(self, probes: F, values: F) -> bytes:
        """What a file's checksum must be: its key, probes and values, byte for byte."""
        h = hashlib.sha256(self.key.encode())
        for a in (probes, values):
            h.update(str(a.shape).encode() + np.ascontiguousarray(a, dtype=np.float64).tobytes())
        return h.digest()

    def __call__(self, probes: F, measure: Callable[[F], F]) -> F:
        cached = self._read(probes)
        if cached is not None:
            self.hits += 1
            return cached
        self.misses += 1
        values = np.asarray(measure(probes), dtype=np.float64)
        buf = io.BytesIO()
        np.savez(
            buf,
            probes=probes,
            values=values,
            sha256=np.frombuffer(self._digest(np.asarray(probes, dtype=np.float64), values), dtype=np.uint8),
        )
        try:
            self.folder.mkdir(parents=True, exist_ok=True)
            atomic_write_bytes(self.path, buf.getvalue())
        except OSError:
            pass  # a read-only or full cache folder only costs the next start its half second
        return values
