"""Saves are a contract: atomic, verified, one-line failures, never over a file the product did not write."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from engine.atomic import WriteError, atomic_write_bytes, set_aside
from tests.faults import full_disk, read_only_folder

HEAD = (b"OURS\n",)


def test_a_save_replaces_the_file_and_leaves_no_temporary(tmp_path: Path) -> None:
    target = tmp_path / "a.json"
    atomic_write_bytes(target, b"OURS\n1")
    atomic_write_bytes(target, b"OURS\n2", expect_head=HEAD)
    assert target.read_bytes() == b"OURS\n2" and [p.name for p in tmp_path.iterdir()] == ["a.json"]


def test_a_full_disk_is_one_line_and_the_old_file_is_intact(tmp_path: Path) -> None:
    with full_disk(tmp_path / "disk") as disk:
        target = disk / "save.json"
        atomic_write_bytes(target, b"OURS\nold")
        with pytest.raises(WriteError) as err:
            atomic_write_bytes(target, b"OURS\n" + os.urandom(64 << 10))
        assert "\n" not in str(err.value) and str(target) in str(err.value) and "space" in str(err.value)
        assert target.read_bytes() == b"OURS\nold"
        assert sorted(p.name for p in disk.iterdir()) == [".filler", "save.json"]


def test_a_read_only_folder_is_one_line(tmp_path: Path) -> None:
    with read_only_folder(tmp_path / "ro") as ro, pytest.raises(WriteError, match="cannot save .*(ermission|ead-only)"):
        atomic_write_bytes(ro / "x.json", b"OURS\n")


def test_a_folder_in_the_way_is_a_write_error_not_a_traceback(tmp_path: Path) -> None:
    (tmp_path / "x.json").mkdir()
    with pytest.raises(WriteError, match="cannot save"):
        atomic_write_bytes(tmp_path / "x.json", b"OURS\n")
    with pytest.raises(WriteError, match="folder"):
        atomic_write_bytes(tmp_path / "x.json", b"OURS\n", expect_head=HEAD)
    assert (tmp_path / "x.json").is_dir()


def test_a_file_the_product_did_not_write_is_never_replaced(tmp_path: Path) -> None:
    mine = tmp_path / "notes.txt"
    mine.write_text("a person's notes")
    with pytest.raises(WriteError, match="not a file this program wrote"):
        atomic_write_bytes(mine, b"OURS\n", expect_head=HEAD)
    assert mine.read_text() == "a person's notes"


def test_only_a_damaged_save_of_ours_is_set_aside(tmp_path: Path) -> None:
    folder, foreign, ours = tmp_path / "folder", tmp_path / "foreign", tmp_path / "ours"
    folder.mkdir()
    foreign.write_text("someone's file")
    ours.write_bytes(b"OURS\ncut sh")
    assert set_aside(folder, HEAD) is None and set_aside(foreign, HEAD) is None
    pipe = tmp_path / "pipe"
    os.mkfifo(pipe)
    assert set_aside(pipe, HEAD) is None and pipe.exists()
    link = tmp_path / "link"
    link.symlink_to(ours)
    assert set_aside(link, HEAD) is None and link.is_symlink()
    Path(f"{ours}.bad").write_text("an earlier one")
    assert set_aside(ours, HEAD) == Path(f"{ours}.1.bad")
    assert Path(f"{ours}.bad").read_text() == "an earlier one" and not ours.exists()
    assert folder.is_dir() and foreign.read_text() == "someone's file"


def test_kill_9_at_any_point_of_a_save_leaves_the_old_or_the_new_file(tmp_path: Path) -> None:
    """The primitive under F5, Ctrl+S, clips add and the batch: a writer killed mid-save loses nothing earlier."""
    import signal
    import subprocess
    import sys
    import time

    import numpy as np

    target = tmp_path / "save.bin"
    old = b"OURS\n" + b"o" * (4 << 20)
    atomic_write_bytes(target, old)
    writer = (
        "import sys\nfrom engine.atomic import atomic_write_bytes\nprint('go', flush=True)\n"
        "while True:\n    atomic_write_bytes(sys.argv[1], b'OURS\\n' + b'n' * (4 << 20))\n"
    )
    delays = np.random.default_rng(30).uniform(0.0, 0.3, 6)
    for delay in delays:
        with subprocess.Popen([sys.executable, "-c", writer, str(target)], stdout=subprocess.PIPE) as proc:
            assert proc.stdout is not None and proc.stdout.readline() == b"go\n"
            time.sleep(float(delay))
            proc.send_signal(signal.SIGKILL)
            proc.wait(10)
        data = target.read_bytes()
        assert data in (old, b"OURS\n" + b"n" * (4 << 20))
    atomic_write_bytes(target, b"OURS\nlast")  # and saving goes on after the kills
    assert target.read_bytes() == b"OURS\nlast"
