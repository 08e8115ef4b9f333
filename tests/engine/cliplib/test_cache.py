"""The lookup measurement cache: the same numbers as measuring, a second start without measuring."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from engine.cliplib.authored import AuthoredClips, authored_locomotion
from engine.cliplib.cache import MeasureCache
from engine.cliplib.roles import conform
from engine.clips import default_clips


def _authored() -> dict:
    return {"walk": conform(default_clips()["walk"].resampled(50.0), "walk")}


def test_second_build_reads_the_cache_and_gives_the_same_table(tmp_path: Path) -> None:
    first, c1 = authored_locomotion(AuthoredClips(_authored(), tmp_path), density=9)
    second, c2 = authored_locomotion(AuthoredClips(_authored(), tmp_path), density=9)
    # Counted, not timed (``warm < cold`` on the wall clock was flaky): the second build measured nothing.
    assert c1 is not None and c2 is not None and (c1.misses, c2.hits, c2.misses) == (1, 1, 0)
    assert np.array_equal(first.table.values, second.table.values)
    uncached, none = authored_locomotion(AuthoredClips(_authored(), None), density=9)
    assert none is None and np.array_equal(uncached.table.values, first.table.values)


def test_other_clips_or_grid_get_another_key(tmp_path: Path) -> None:
    a = MeasureCache(tmp_path, "clips-a:9")
    assert a.path != MeasureCache(tmp_path, "clips-b:9").path != MeasureCache(tmp_path, "clips-a:31").path


def test_other_kernels_numpy_is_held_at_get_another_key(tmp_path: Path, monkeypatch) -> None:
    """A table measured on an AVX-512 machine's OpenBLAS kernels parted a crowd's state from the one the
    launcher's AVX2 cap measures: numbers from other kernels must not be read back."""
    monkeypatch.delenv("OPENBLAS_CORETYPE", raising=False)
    plain = MeasureCache(tmp_path, "clips-a:9").path
    monkeypatch.setenv("OPENBLAS_CORETYPE", "Haswell")
    capped = MeasureCache(tmp_path, "clips-a:9").path
    monkeypatch.setenv("NPY_DISABLE_CPU_FEATURES", "X86_V3")
    assert len({plain, capped, MeasureCache(tmp_path, "clips-a:9").path}) == 3


def test_a_damaged_cache_file_is_measured_again(tmp_path: Path) -> None:
    probes = np.linspace(0.0, 1.0, 8).reshape(4, 2)
    cache = MeasureCache(tmp_path, "k")
    calls = []

    def measure(p: np.ndarray) -> np.ndarray:
        calls.append(1)
        return p * 2.0

    assert np.array_equal(cache(probes, measure), probes * 2.0)
    cache.path.write_bytes(b"PK\x03\x04 broken")
    assert np.array_equal(cache(probes, measure), probes * 2.0)
    assert np.array_equal(cache(probes, measure), probes * 2.0)
    assert len(calls) == 2 and cache.hits == 1
    assert np.array_equal(cache(probes[:2], measure), probes[:2] * 2.0)  # other probes: not this entry
    assert len(calls) == 3


def test_a_tampered_cache_file_is_measured_again(tmp_path: Path) -> None:
    """Values edited in place (finite, right shape) must not change what the game plays."""
    import io

    from engine.npz_safe import read_npz

    probes = np.linspace(0.0, 1.0, 8).reshape(4, 2)
    measure = lambda p: p.sum(axis=1, keepdims=True) * 2.0  # noqa: E731
    cache = MeasureCache(tmp_path, "k")
    first = cache(probes, measure)
    arrays = read_npz(cache.path.read_bytes())
    arrays["values"] = arrays["values"] + 1.0
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    cache.path.write_bytes(buf.getvalue())
    again = MeasureCache(tmp_path, "k")
    assert np.array_equal(again(probes, measure), first) and again.misses == 1 and again.hits == 0
