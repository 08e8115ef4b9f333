"""A refused save goes to the recovery folder: the same bytes, a free name, never over earlier recovered work."""

from __future__ import annotations

from pathlib import Path

import pytest

from engine.atomic import atomic_write_bytes
from engine.recovery import Rescue, recovery_folder
from tests.faults import full_disk, read_only_folder


def _write(data: bytes):  # type: ignore[no-untyped-def]
    return lambda path: atomic_write_bytes(path, data)


def test_a_save_that_its_file_takes_goes_nowhere_else(tmp_path: Path) -> None:
    saved = Rescue(tmp_path / "a.json").save(_write(b"1"))
    assert saved.path == tmp_path / "a.json" and not saved.why and not recovery_folder().exists()


def test_a_refused_save_is_kept_in_the_recovery_folder_and_retried_at_its_file(tmp_path: Path) -> None:
    with read_only_folder(tmp_path / "ro") as ro:
        rescue = Rescue(ro / "field.json")
        first = rescue.save(_write(b"first"))
        second = rescue.save(_write(b"second"))  # F5 again: the same recovery file, not a new one each time
    assert first.recovered and first.path == recovery_folder() / "field.json" and "field.json" in first.why
    assert second.path == first.path and first.path.read_bytes() == b"second"
    assert sorted(p.name for p in recovery_folder().iterdir()) == ["field.json"]
    assert rescue.save(_write(b"third")).path == ro / "field.json"  # the folder is writable again: back home
    assert (ro / "field.json").read_bytes() == b"third"


def test_a_later_session_never_overwrites_earlier_recovered_work(tmp_path: Path) -> None:
    (tmp_path / "field.json").mkdir()  # a folder in the way
    recovery_folder().mkdir(parents=True)
    (recovery_folder() / "field.json").write_bytes(b"last week's")
    saved = Rescue(tmp_path / "field.json").save(_write(b"today's"))
    assert saved.path == recovery_folder() / "field.1.json" and saved.path.read_bytes() == b"today's"
    assert (recovery_folder() / "field.json").read_bytes() == b"last week's"


def test_a_full_disk_everywhere_is_one_line_and_nothing_is_written(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    with full_disk(tmp_path / "disk") as disk:
        monkeypatch.setenv("XDG_DATA_HOME", str(disk / "data"))
        saved = Rescue(disk / "field.json").save(_write(b"x" * (64 << 10)))
        assert saved.path is None and "space" in saved.why and "\n" not in saved.why
        assert str(disk / "data") in saved.why
        assert "NOT saved" in saved.line("field", disk / "field.json")
