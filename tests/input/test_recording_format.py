"""The recording file format at its boundaries, written and read without an app (fast enough for mutmut).

Each test states what a reader or writer must do with one kind of file; the mutation run over
``input/recording.py`` (docs/mutation.md) is the check that each can fail: e.g. the header's
``0 < len(game) <= 64`` made ``< 64`` fails ``test_header_limits_are_inclusive``, the names block
written on every record fails ``test_part_names_are_written_only_when_they_change``.
"""

from __future__ import annotations

import json
import struct
import zlib
from pathlib import Path

import numpy as np
import pytest

from input.codec import encode_frame
from input.recording import (
    CLOSING_FORMAT,
    FORMAT_VERSION,
    MAGIC,
    MAX_DT,
    MAX_HEADER,
    MIN_DT,
    Recorder,
    RecordingError,
    RecordingHeader,
    read_recording,
)
from input.sample import InputFrame, PoseSample

_LEN = struct.Struct("<II")
HASH = "00112233445566778899aabbccddeeff"


def frame(i: int) -> InputFrame:
    """A frame with one phone sample, so every record decodes to something checkable."""
    q = np.array([np.cos(i / 10), np.sin(i / 10), 0.0, 0.0])
    return InputFrame(
        frame=i, samples=(PoseSample(time=i / 60, source="osc:10.0.0.2", orientation=q, touch=i % 2 == 0),)
    )


def header_bytes(d: object) -> bytes:
    head = json.dumps(d).encode()
    return MAGIC + _LEN.pack(len(head), zlib.crc32(head)) + head


def record(payload: bytes) -> bytes:
    return _LEN.pack(len(payload), zlib.crc32(payload)) + payload


def records_start(data: bytes) -> int:
    """Where the first record starts: after the magic, the length and checksum, and the header."""
    return len(MAGIC) + _LEN.size + _LEN.unpack_from(data, len(MAGIC))[0]


def old_file(path: Path, fmt: int, frames: int) -> Path:
    """A file in an older format: records of hash + frame (before parts, format < 3) and no closing record."""
    body = b"".join(record(bytes.fromhex(HASH) + encode_frame(frame(i))) for i in range(frames))
    path.write_bytes(header_bytes({"game": "g", "seed": 1, "dt": 0.02, "format": fmt}) + body)
    return path


def write(path: Path, parts: list[dict[str, bytes]], header: RecordingHeader | None = None) -> Recorder:
    rec = Recorder(
        path,
        header
        or RecordingHeader(
            game="g",
            seed=3,
            dt=0.02,
            sources=["osc"],
            setup={"k": [1, 2]},
            extra={"note": "x"},
            libraries={"numpy": "2.0.0"},
        ),
    )
    for i, p in enumerate(parts):
        rec.write(frame(i), HASH[2 * i % 8 :] + HASH[: 2 * i % 8], p)
    return rec


def test_a_recording_reads_back_exactly_what_was_written(tmp_path: Path) -> None:
    """Header, frames, hashes and part digests come back as written; the file is complete and not cut."""
    parts = [{"A": b"\x01\x02", "B": b"\x03\x04"}, {"A": b"\x05\x06", "B": b"\x07\x08"}, {"C": b"\x09\x0a"}]
    with write(tmp_path / "s.rec", parts) as rec:
        pass
    assert rec.frames == 3 and rec.bytes + _LEN.size == (tmp_path / "s.rec").stat().st_size and rec.failed == ""
    r = read_recording(tmp_path / "s.rec")
    assert r.complete and not r.cut and r.problem == "" and len(r) == 3
    h = r.header
    assert (h.game, h.seed, h.dt, h.sources, h.setup, h.extra, h.libraries, h.format) == (
        "g",
        3,
        0.02,
        ["osc"],
        {"k": [1, 2]},
        {"note": "x"},
        {"numpy": "2.0.0"},
        FORMAT_VERSION,
    )
    assert r.parts == parts
    assert r.hashes == [HASH[2 * i % 8 :] + HASH[: 2 * i % 8] for i in range(3)]
    assert [f.frame for f in r.frames] == [0, 1, 2]
    np.testing.assert_array_equal(r.frames[2].samples[0].orientation, frame(2).samples[0].orientation)
    assert r.frames[1].samples[0].touch is False


def test_part_names_are_written_only_when_they_change(tmp_path: Path) -> None:
    """The names block (flag 1, u16 length, names) appears on the first record and on a change only."""
    same = {"Alpha": b"\x00\x01", "Beta": b"\x00\x02"}
    rec = write(tmp_path / "s.rec", [same, same, same])
    sizes = []
    data = (tmp_path / "s.rec").read_bytes()
    pos = records_start(data)
    for _ in range(3):
        n, _crc = _LEN.unpack_from(data, pos)
        sizes.append(n)
        pos += _LEN.size + n
    listed = len(b"Alpha\nBeta")
    assert sizes[0] - sizes[1] == 2 + listed and sizes[1] == sizes[2]
    rec.close()
    assert read_recording(tmp_path / "s.rec").parts == [same] * 3


def _asdict(h: RecordingHeader) -> dict[str, object]:
    from dataclasses import asdict

    return asdict(h)


def test_no_parts_and_the_most_parts_a_record_holds(tmp_path: Path) -> None:
    """A record with no parts reads as ``{}``; 255 parts fit; 256 are refused with a clear error."""
    many = {f"p{i}": bytes([i % 256, 1]) for i in range(255)}
    with write(tmp_path / "s.rec", [{}, many]):
        pass
    assert read_recording(tmp_path / "s.rec").parts == [{}, many]
    rec = write(tmp_path / "t.rec", [])
    with pytest.raises(RecordingError, match="256 state parts; a record holds at most 255"):
        rec.write(frame(0), HASH, {f"p{i}": b"\x00\x00" for i in range(256)})
    rec.close()


def test_a_closed_recorder_refuses_to_write_and_closes_once(tmp_path: Path) -> None:
    rec = write(tmp_path / "s.rec", [{"A": b"\x00\x01"}])
    rec.close()
    size = (tmp_path / "s.rec").stat().st_size
    rec.close()
    assert (tmp_path / "s.rec").stat().st_size == size  # no second closing record
    with pytest.raises(RecordingError, match="is closed"):
        rec.write(frame(1), HASH, {})
    assert read_recording(tmp_path / "s.rec").complete


def test_the_closing_record_counts_the_frames_and_ends_the_file(tmp_path: Path) -> None:
    """A closing record with the wrong count, or bytes after it, is damage; a file without it is cut."""
    path = tmp_path / "s.rec"
    with write(path, [{}, {}]):
        pass
    good = path.read_bytes()
    body = good[: -_LEN.size]
    path.write_bytes(body + _LEN.pack(0, 3))
    r = read_recording(path)
    assert not r.complete and not r.cut and r.problem.startswith("damaged closing record after frame 2")
    assert len(r) == 2
    path.write_bytes(good + b"\x00")
    assert read_recording(path).problem.startswith("damaged closing record after frame 2")
    path.write_bytes(body)
    r = read_recording(path)
    assert r.cut and not r.complete and len(r) == 2
    assert r.problem == "cut: ended without its closing record after 2 frames (killed mid-session?)"


@pytest.mark.parametrize("fmt", [1, 2])
def test_an_old_recording_without_parts_or_closing_record_is_complete(tmp_path: Path, fmt: int) -> None:
    r = read_recording(old_file(tmp_path / "o.rec", fmt, 3))
    assert r.complete and not r.cut and r.problem == "" and len(r) == 3 and r.parts == []
    assert r.hashes == [HASH] * 3 and r.header.libraries == {} and r.header.format == fmt


def test_format_3_has_parts_but_no_closing_record(tmp_path: Path) -> None:
    """Format 3 files (before the closing record) read complete; a zero length there is a damaged record."""
    assert CLOSING_FORMAT == 4
    payload = (
        bytes.fromhex(HASH) + b"\x01" + struct.pack("<H", 1) + b"A" + b"\x01" + b"\x07\x08" + encode_frame(frame(0))
    )
    path = tmp_path / "3.rec"
    path.write_bytes(header_bytes({"game": "g", "seed": 1, "dt": 0.02, "format": 3}) + record(payload))
    r = read_recording(path)
    assert r.complete and r.parts == [{"A": b"\x07\x08"}]
    path.write_bytes(path.read_bytes() + _LEN.pack(0, 1))
    r = read_recording(path)
    assert not r.complete and r.problem.startswith("damaged record at frame 1")


def test_cut_and_damaged_records_are_told_apart(tmp_path: Path) -> None:
    """A cut inside a length or a payload is ``cut``; a checksum or a too-short payload is damage."""
    path = tmp_path / "s.rec"
    with write(path, [{}, {}]):
        pass
    data = path.read_bytes()
    start = len(data) - _LEN.size
    n1 = _LEN.unpack_from(data, records_start(data))[0]
    second = start - (_LEN.size + n1)
    for cut_at, says in [
        (second + 3, f"cut inside the record of frame 1 (byte {second})"),
        (second + _LEN.size + 5, f"cut inside the record of frame 1 (byte {second})"),
    ]:
        path.write_bytes(data[:cut_at])
        r = read_recording(path)
        assert r.cut and not r.complete and r.problem == says and len(r) == 1 and len(r.parts) == 1
    flipped = bytearray(data)
    flipped[second + _LEN.size + 1] ^= 0xFF
    path.write_bytes(bytes(flipped))
    r = read_recording(path)
    assert not r.cut and r.problem == f"damaged record at frame 1 (byte {second}, checksum mismatch)" and len(r) == 1
    short = data[:second] + record(b"\x00" * 15)
    path.write_bytes(short)
    assert read_recording(path).problem == f"damaged record at frame 1 (byte {second}, checksum mismatch)"


def _one_record_file(path: Path, payload: bytes) -> Path:
    path.write_bytes(header_bytes({"game": "g", "seed": 1, "dt": 0.02}) + record(payload))
    return path


@pytest.mark.parametrize(
    "parts,says",
    [
        (b"", "record too short for its parts"),
        (b"\x00", "record too short for its parts"),
        (b"\x00\x01", "1 part digests for 0 part names"),
        (b"\x01\x05\x00AB", "part names cut short"),
        (b"\x01\x02\x00\xff\xfe\x01\x00\x00", "part names are not UTF-8"),
        (b"\x01\x01\x00A", "record too short for its parts"),
        (b"\x01\x03\x00A\nB\x02\x00\x00\x00", "2 part digests for 2 part names"),
        (b"\x01\x03\x00A\nB\x01\x00\x00", "1 part digests for 2 part names"),
    ],
)
def test_a_broken_parts_block_is_an_undecodable_record(tmp_path: Path, parts: bytes, says: str) -> None:
    r = read_recording(_one_record_file(tmp_path / "p.rec", bytes.fromhex(HASH) + parts))
    assert not r.complete and not r.cut and len(r) == 0 and r.problem == f"undecodable record at frame 0: {says}"


def test_an_empty_names_block_means_no_parts(tmp_path: Path) -> None:
    payload = bytes.fromhex(HASH) + b"\x01\x00\x00\x00" + encode_frame(frame(0))
    path = _one_record_file(tmp_path / "e.rec", payload)
    path.write_bytes(path.read_bytes() + _LEN.pack(0, 1))
    r = read_recording(path)
    assert r.complete and r.parts == [{}] and len(r) == 1


def test_a_frame_that_does_not_decode_is_named(tmp_path: Path) -> None:
    r = read_recording(_one_record_file(tmp_path / "f.rec", bytes.fromhex(HASH) + b"\x00\x00" + b"\x01"))
    assert not r.complete and r.problem.startswith("undecodable record at frame 0: ") and len(r) == 0


def base(**over: object) -> dict[str, object]:
    return {"game": "g", "seed": 0, "dt": 0.02, **over}


@pytest.mark.parametrize(
    "d",
    [
        base(game="x" * 64),
        base(game="x"),
        base(seed=2**63 - 1),
        base(seed=0),
        base(dt=MIN_DT),
        base(dt=MAX_DT),
        base(dt=1),
        base(format=1),
        base(sources=[]),
        base(sources=["a", "b"]),
        base(engine_version="1.2"),
        base(extra={}),
        base(libraries={}),
        base(setup={"a": 1}),
    ],
)
def test_header_limits_are_inclusive(tmp_path: Path, d: dict[str, object]) -> None:
    path = tmp_path / "h.rec"
    fmt = d.get("format", FORMAT_VERSION)
    closing = _LEN.pack(0, 0) if isinstance(fmt, int) and fmt >= CLOSING_FORMAT else b""
    path.write_bytes(header_bytes(d) + closing)
    r = read_recording(path)
    assert r.complete and r.header.game == d["game"] and r.header.seed == d["seed"] and r.header.dt == d["dt"]


@pytest.mark.parametrize(
    "d,says",
    [
        (base(game=""), "bad header: game must be a name of 1..64 characters"),
        (base(game="x" * 65), "bad header: game must be a name of 1..64 characters"),
        (base(seed=2**63), "bad header: seed must be a whole number in 0..2\\*\\*63-1"),
        (base(seed=1.0), "bad header: seed must be"),
        (base(dt=MIN_DT * 0.99), f"bad header: dt must be a number of seconds in \\[{MIN_DT}, {MAX_DT}\\]"),
        (base(dt=MAX_DT * 1.01), "bad header: dt must be"),
        (base(dt=True), "bad header: dt must be"),
        (base(format=0), "bad header: format must be a whole number from 1"),
        (base(format=True), "bad header: format must be"),
        (base(sources=[1]), "bad header: sources must be a list of names"),
        (base(engine_version=1), "bad header: engine_version must be a string and extra an object"),
        (base(libraries=[]), "bad header: libraries must be an object"),
        (base(setup=[]), "bad header: setup must be an object"),
        (base(zz=1, aa=2), "bad header: unknown fields 'aa', 'zz'"),
        ([1, 2], "bad header: not a JSON object$"),
        ({"game": "g"}, "bad header: missing dt, seed"),
        (base(format=FORMAT_VERSION + 1), f"is format {FORMAT_VERSION + 1}; this build reads up to {FORMAT_VERSION}"),
    ],
)
def test_a_bad_header_is_refused_with_one_line(tmp_path: Path, d: object, says: str) -> None:
    path = tmp_path / "h.rec"
    path.write_bytes(header_bytes(d) + _LEN.pack(0, 0))
    with pytest.raises(RecordingError, match=says):
        read_recording(path)


def test_an_unknown_field_list_is_cut_short(tmp_path: Path) -> None:
    path = tmp_path / "h.rec"
    path.write_bytes(header_bytes(base(**{f"f{i:03d}": 1 for i in range(50)})))
    with pytest.raises(RecordingError) as err:
        read_recording(path)
    listed = str(err.value).split("unknown fields ", 1)[1]
    assert len(listed) == 100 and listed.startswith("'f000', 'f001'")


def test_header_damage_is_named(tmp_path: Path) -> None:
    path = tmp_path / "h.rec"
    good = header_bytes(base())
    cases = [
        (b"PPREC!" + good[6:], "is not a PuppetPhone recording (bad magic)"),
        (good[:9], "is cut inside its header"),
        (good[:-1], "is cut inside its header"),
        (good[:-2] + b"x}", "has a damaged header (checksum mismatch)"),
        (MAGIC + _LEN.pack(MAX_HEADER + 1, 0), f"claims a {MAX_HEADER + 1}-byte header; the limit is {MAX_HEADER}"),
    ]
    bad_json = b"{nope"
    cases.append(
        (MAGIC + _LEN.pack(len(bad_json), zlib.crc32(bad_json)) + bad_json, "has an unreadable header: JSONDecodeError")
    )
    for data, says in cases:
        path.write_bytes(data)
        with pytest.raises(RecordingError) as err:
            read_recording(path)
        assert str(err.value) == f"{path} {says}"
    path.write_bytes(MAGIC + _LEN.pack(MAX_HEADER, 0))
    with pytest.raises(RecordingError, match="cut inside its header"):  # the limit itself is allowed
        read_recording(path)


def test_the_recorder_writes_the_header_as_sorted_json(tmp_path: Path) -> None:
    rec = write(tmp_path / "s.rec", [])
    rec.close()
    data = (tmp_path / "s.rec").read_bytes()
    n, crc = _LEN.unpack_from(data, len(MAGIC))
    head = data[len(MAGIC) + _LEN.size : len(MAGIC) + _LEN.size + n]
    assert data.startswith(MAGIC) and zlib.crc32(head) == crc
    assert head == json.dumps(_asdict(rec.header), sort_keys=True).encode()
    assert data[len(MAGIC) + _LEN.size + n :] == _LEN.pack(0, 0)


def test_long_part_names_fit_the_names_block(tmp_path: Path) -> None:
    """The names block's length is unsigned 16-bit: 36 KB of names (past a signed length) read back."""
    parts = {name * 12_000: b"\x01\x02" for name in "abc"}
    with write(tmp_path / "s.rec", [parts, parts]):
        pass
    assert read_recording(tmp_path / "s.rec").parts == [parts, parts]


def test_parts_that_end_the_record_leave_an_empty_frame(tmp_path: Path) -> None:
    """Digests that fill the record exactly are fine; the frame after them is what is missing."""
    r = read_recording(_one_record_file(tmp_path / "p.rec", bytes.fromhex(HASH) + b"\x01\x01\x00A\x01\x00\x00"))
    assert r.problem.startswith("undecodable record at frame 0: ") and "part digests" not in r.problem


def test_the_header_names_the_engine_version_or_says_unknown(monkeypatch: pytest.MonkeyPatch) -> None:
    import importlib.metadata

    assert RecordingHeader(game="g", seed=0, dt=0.02).engine_version == importlib.metadata.version("puppetphone")

    def missing(name: str) -> str:
        raise importlib.metadata.PackageNotFoundError(name)

    monkeypatch.setattr(importlib.metadata, "version", missing)
    assert RecordingHeader(game="g", seed=0, dt=0.02).engine_version == "unknown"  # a bare checkout
