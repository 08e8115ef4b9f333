"""The built-in locomotion table is measured once per user, then read back from the cache folder."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from engine.blend.puppet import build_locomotion, builtin_cache, puppet_locomotion
from engine.clips import default_clips


def test_the_second_start_reads_the_table_instead_of_measuring(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    clips = default_clips()
    first = builtin_cache(clips, density=5)
    measured = build_locomotion(clips, density=5, memo=first)
    assert (first.hits, first.misses) == (0, 1)
    assert first.path.parent == tmp_path / "puppetphone" / "lookup" and first.path.exists()
    second = builtin_cache(clips, density=5)
    read = build_locomotion(clips, density=5, memo=second)
    assert (second.hits, second.misses) == (1, 0)
    np.testing.assert_array_equal(read.table.values, measured.table.values)
    other = builtin_cache(clips, density=7)  # another grid is another key
    assert other.path != first.path


def test_a_damaged_cache_file_is_measured_again(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    clips = default_clips()
    good = build_locomotion(clips, density=5, memo=builtin_cache(clips, density=5))
    path = builtin_cache(clips, density=5).path
    raw = bytearray(path.read_bytes())
    raw[len(raw) // 2] ^= 0xFF
    path.write_bytes(bytes(raw))
    again = builtin_cache(clips, density=5)
    table = build_locomotion(clips, density=5, memo=again)
    assert again.misses == 1
    np.testing.assert_array_equal(table.table.values, good.table.values)


def test_the_default_set_goes_through_the_cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    puppet_locomotion.cache_clear()
    try:
        puppet_locomotion(density=5)
    finally:
        puppet_locomotion.cache_clear()
    assert list((tmp_path / "puppetphone" / "lookup").glob("*.npz"))
