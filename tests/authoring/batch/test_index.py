"""The library index: one transaction per take, options kept, a reader for other commands."""

from __future__ import annotations

import hashlib
import sqlite3
from pathlib import Path

import pytest

from authoring.batch.index import LibraryIndex, LibraryIndexError, read_index
from authoring.batch.runner import collect_sources, licence_of
from authoring.batch.worker import ClipOut, TakeOutcome


def _outcome(digest: str, clips: int) -> TakeOutcome:
    cs = tuple(ClipOut(k, 10 * k, 10 * k + 10, k / 6, k / 6 + 1.0, 1.0, 3, 0.0, 0.1, 1.2, 7, "walk", ".npz", b"x%d" % k)
               for k in range(clips))
    return TakeOutcome(f"/d/{digest}.bvh", digest, "looped" if clips else "refused", "" if clips else "no period",
                       100, 60.0, 7, 0.5, cs)


def _files(root: Path, outcome: TakeOutcome, files: list[str]) -> list[str]:
    """Write the take's clip files as the batch does before it records them."""
    for clip, rel in zip(outcome.clips, files, strict=True):
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        (root / rel).write_bytes(clip.data)
    return files


def test_record_and_read_back_sorted(tmp_path: Path) -> None:
    index = LibraryIndex(tmp_path, "opts")
    _files(tmp_path, _outcome("bbb", 2), ["clips/b0.npz", "clips/b1.npz"])
    index.record(_outcome("bbb", 2), ["clips/b0.npz", "clips/b1.npz"], "CC0")
    index.record(_outcome("aaa", 0), [], "unknown")
    index.record(_outcome("bbb", 1), ["clips/b0.npz"], "CC0")  # redone: its clips replaced, not added
    assert index.known_hashes() == {"aaa", "bbb"}
    index.close()
    takes, clips = read_index(tmp_path)
    assert [t.hash for t in takes] == ["aaa", "bbb"] and takes[0].reason == "no period"
    assert [c.file for c in clips] == ["clips/b0.npz"] and clips[0].path == tmp_path / "clips/b0.npz"
    assert clips[0].kind == "walk" and clips[0].speed == 1.2 and clips[0].licence == "CC0"


def test_other_options_newer_schema_and_garbage_are_refused(tmp_path: Path) -> None:
    LibraryIndex(tmp_path, "retarget=none").close()
    with pytest.raises(LibraryIndexError, match="was built with retarget=none"):
        LibraryIndex(tmp_path, "retarget=puppet")
    con = sqlite3.connect(tmp_path / "index.sqlite")
    con.execute("UPDATE meta SET value = '99' WHERE key = 'schema'")
    con.commit()
    con.close()
    with pytest.raises(LibraryIndexError, match="schema 99"):
        LibraryIndex(tmp_path, "retarget=none")
    bad = tmp_path / "bad"
    bad.mkdir()
    (bad / "index.sqlite").write_bytes(b"not a database at all" * 100)
    with pytest.raises(LibraryIndexError):
        LibraryIndex(bad, "x")
    with pytest.raises(LibraryIndexError):
        read_index(bad)
    with pytest.raises(LibraryIndexError, match="no library index"):
        read_index(tmp_path / "none")


def test_sources_files_folders_globs_once_each(tmp_path: Path) -> None:
    (tmp_path / "a").mkdir()
    for name in ("a/x.bvh", "a/y.csv", "a/z.txt", "w.npz"):
        (tmp_path / name).write_text("")
    found = collect_sources([str(tmp_path / "a"), str(tmp_path / "a" / "x.bvh"), str(tmp_path / "*.npz")], (".bvh", ".csv", ".npz"))
    assert [p.name for p in found] == ["x.bvh", "y.csv", "w.npz"]


def test_licence_given_known_or_unknown() -> None:
    assert licence_of("/x/bandai1_walk.bvh", None).startswith("CC BY-NC")
    assert licence_of("/x/cmu_16_15.bvh", None).startswith("CMU")
    assert licence_of("/x/mine.bvh", None) == "unknown" and licence_of("/x/cmu.bvh", "CC0") == "CC0"


def test_the_library_inside_a_source_folder_is_not_a_source(tmp_path: Path) -> None:
    (tmp_path / "lib" / "clips").mkdir(parents=True)
    (tmp_path / "take.npz").write_text("")
    (tmp_path / "lib" / "clips" / "take-0.npz").write_text("")
    assert [p.name for p in collect_sources([str(tmp_path)], (".npz",), exclude=tmp_path / "lib")] == ["take.npz"]
    assert len(collect_sources([str(tmp_path)], (".npz",))) == 2


def test_a_take_counts_as_done_only_with_its_clip_files_intact(tmp_path: Path) -> None:
    index = LibraryIndex(tmp_path, "opts")
    for digest in ("aaa", "bbb", "ccc"):
        outcome = _outcome(digest, 2)
        index.record(outcome, _files(tmp_path, outcome, [f"clips/{digest}{k}.npz" for k in range(2)]), "CC0")
    assert index.known_hashes() == {"aaa", "bbb", "ccc"}
    (tmp_path / "clips/aaa1.npz").unlink()  # a deleted clip file
    (tmp_path / "clips/bbb0.npz").write_bytes(b"changed")  # an altered one
    assert index.known_hashes() == {"ccc"}
    index.close()


def test_a_flipped_byte_in_a_clip_row_means_the_take_is_done_again(tmp_path: Path) -> None:
    index = LibraryIndex(tmp_path, "opts")
    outcome = _outcome("aaa", 1)
    index.record(outcome, _files(tmp_path, outcome, ["clips/a0.npz"]), "CC0")
    index.close()
    data = bytearray((tmp_path / "index.sqlite").read_bytes())
    at = data.find(hashlib.sha256(b"x0").hexdigest().encode())
    assert at > 0
    data[at + 5] ^= 0x01
    (tmp_path / "index.sqlite").write_bytes(bytes(data))
    assert LibraryIndex(tmp_path, "opts").known_hashes() == set()


def test_a_damaged_page_or_a_bad_schema_value_is_one_line(tmp_path: Path) -> None:
    LibraryIndex(tmp_path, "opts").close()
    con = sqlite3.connect(tmp_path / "index.sqlite")
    con.execute("UPDATE meta SET value = 'abc' WHERE key = 'schema'")
    con.commit()
    con.close()
    with pytest.raises(LibraryIndexError, match="not a version number"):
        LibraryIndex(tmp_path, "opts")
    (tmp_path / "b").mkdir()
    index = LibraryIndex(tmp_path / "b", "opts")
    outcome = _outcome("aaa", 3)
    index.record(outcome, _files(tmp_path / "b", outcome, [f"clips/a{k}.npz" for k in range(3)]), "CC0")
    index.close()
    data = bytearray((tmp_path / "b" / "index.sqlite").read_bytes())
    data[4096 * 2: 4096 * 2 + 12] = b"\xff" * 12  # a b-tree page's header
    (tmp_path / "b" / "index.sqlite").write_bytes(bytes(data))
    with pytest.raises(LibraryIndexError, match="damaged|not a library index"):
        LibraryIndex(tmp_path / "b", "opts")
