"""Recording and bit-exact replay: every hash matches, a cut file recovers every complete frame."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from engine import quat
from input.hub import InputHub
from input.recording import FORMAT_VERSION, MAGIC, Recorder, RecordingError, RecordingHeader, read_recording
from input.replay import ReplaySource, verify
from input.sample import PoseSample
from input.source import PoseSource


class Fed(PoseSource):
    threaded = False


def record_session(make_app, path, steps=120, source="osc:192.168.1.23"):
    """Drive a phone-like source through grab, move and release, recording every step."""
    src = Fed("phone")
    app = make_app(InputHub([src]))
    rec = Recorder(path, RecordingHeader(game="test", seed=7, dt=app.world.dt, sources=["phone"])).attach(app)
    rng = np.random.default_rng(5)
    for i in range(steps):
        pitch = -0.3 + 0.2 * np.sin(i / 15) + rng.normal(0, 0.002)
        q = quat.from_axis_angle([1.0, 0.0, 0.0], pitch)
        src.push(
            PoseSample(
                time=i / 60,
                source=source,
                orientation=q,
                angular_velocity=rng.normal(0, 1, 3),
                acceleration=[0.0, 9.81, 0.0],
                touch=(i in range(3, 5)) or (i >= 10 and i < 90),
            )
        )
        app.step()
    rec.close()
    return app, rec


def test_record_then_replay_every_hash_matches(make_app, tmp_path):
    path = tmp_path / "s.rec"
    app, rec = record_session(make_app, path)
    r = read_recording(path)
    assert r.complete and len(r) == 120 and r.header.game == "test" and r.header.seed == 7
    assert r.header.format == FORMAT_VERSION and r.header.sources == ["phone"] and r.header.engine_version
    res = verify(make_app, r)
    assert res.ok and res.message() == "replayed 120 frames, all 120 state hashes match"


def test_a_tampered_frame_is_named(make_app, tmp_path):
    path = tmp_path / "s.rec"
    record_session(make_app, path, steps=40)
    r = read_recording(path)
    r.frames[25].samples[0].orientation[1] += 1e-12  # one ulp-ish change in frame 25's input
    res = verify(make_app, r)
    assert not res.ok and res.first_mismatch == 25 and res.matched == 25
    assert "frame 25" in res.message()


def test_cut_at_any_byte_recovers_every_complete_frame(make_app, tmp_path):
    path = tmp_path / "s.rec"
    record_session(make_app, path, steps=30)
    data = path.read_bytes()
    full = read_recording(path)
    # Record boundaries: after the header, then after each record.
    pos = len(MAGIC) + 8 + int.from_bytes(data[len(MAGIC) : len(MAGIC) + 4], "little")
    first, ends = pos, []
    while pos < len(data):
        pos += 8 + int.from_bytes(data[pos : pos + 4], "little")
        ends.append(pos)
    assert ends[-1] == len(data) and len(ends) == 31  # 30 records and the closing one
    assert full.complete and len(full) == 30
    ends = ends[:-1]
    cuts = np.random.default_rng(0).choice(np.arange(first, len(data)), 60, replace=False)
    for cut in sorted([*cuts, *ends[::7]]):
        p = tmp_path / "cut.rec"
        p.write_bytes(data[:cut])
        r = read_recording(p)
        whole = sum(1 for e in ends if e <= cut)
        assert len(r) == whole and not r.complete and r.cut  # a cut between records is a cut too
        assert r.hashes == full.hashes[:whole]
        assert ("ended without its closing record" if cut in ends or cut == first else "cut inside") in r.problem


def test_a_cut_recording_still_replays_its_complete_frames(make_app, tmp_path):
    path = tmp_path / "s.rec"
    record_session(make_app, path, steps=50)
    data = path.read_bytes()
    path.write_bytes(data[: len(data) - 37])
    r = read_recording(path)
    assert not r.complete and len(r) == 49
    assert verify(make_app, r).ok


def test_damaged_byte_and_bad_headers(make_app, tmp_path):
    path = tmp_path / "s.rec"
    record_session(make_app, path, steps=10)
    data = bytearray(path.read_bytes())
    data[-13] ^= 0xFF  # inside the last record (the closing record is the last 8 bytes)
    path.write_bytes(bytes(data))
    r = read_recording(path)
    assert len(r) == 9 and "checksum" in r.problem and not r.cut
    for bad, msg in (
        (b"not a recording", "bad magic"),
        (MAGIC + b"\x05", "cut inside its header"),
        (bytes(data[:20]), "cut inside its header"),
    ):
        path.write_bytes(bad)
        with pytest.raises(RecordingError, match=msg):
            read_recording(path)
    head = bytearray(data)
    head[len(MAGIC) + 10] ^= 1
    path.write_bytes(bytes(head))
    with pytest.raises(RecordingError, match="damaged header"):
        read_recording(path)


def test_file_grows_as_frames_are_written(make_app, tmp_path):
    path = tmp_path / "live.rec"
    src = Fed("m")
    app = make_app(InputHub([src]))
    rec = Recorder(path, RecordingHeader(game="t", seed=7, dt=app.world.dt)).attach(app)
    sizes = []
    for _ in range(3):
        app.step()
        sizes.append(path.stat().st_size)  # flushed without closing
    open_now = read_recording(path)
    assert sizes[0] < sizes[1] < sizes[2] and len(open_now) == 3 and "closing record" in open_now.problem
    rec.close()
    assert read_recording(path).complete and len(read_recording(path)) == 3


def test_a_closing_record_that_does_not_match_is_damage(make_app, tmp_path):
    path = tmp_path / "s.rec"
    record_session(make_app, path, steps=5)
    data = bytearray(path.read_bytes())
    data[-4] = 9  # claims 9 frames
    path.write_bytes(bytes(data))
    assert "damaged closing record" in read_recording(path).problem
    path.write_bytes(bytes(data[:-4]) + (5).to_bytes(4, "little") + b"junk")
    assert "damaged closing record" in read_recording(path).problem


def _record_400_steps(make_app, path: Path) -> tuple[Recorder, object]:  # type: ignore[no-untyped-def]
    src = Fed("m")
    app = make_app(InputHub([src]))
    rec = Recorder(path, RecordingHeader(game="t", seed=7, dt=app.world.dt)).attach(app)
    for i in range(400):  # ~100 bytes a record: the disk fills long before the end
        src.push(PoseSample(time=i / 60, source="osc:1", orientation=quat.from_axis_angle([1, 0, 0], 0.01 * i)))
        app.step()
    rec.close()
    return rec, app


def test_a_full_disk_moves_the_recording_to_the_recovery_folder_whole(make_app, tmp_path, capsys, monkeypatch):
    """Nothing is lost: the frames already on the full disk and every later one end up, in order and
    closed, in the recovery folder (broken on purpose: with the move removed the recording stopped
    at frame ~77 of 400)."""
    from tests.faults import full_disk

    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))
    with full_disk(tmp_path / "disk", free=8192) as disk:
        rec, app = _record_400_steps(make_app, disk / "s.rec")
        assert app.world.frame == 400 and not rec.failed and rec.frames == 400
        err = capsys.readouterr().err
        assert err.count("it goes on in") == 1 and "Traceback" not in err and len(err.strip().splitlines()) == 1
        moved = tmp_path / "data" / "puppetphone" / "recovered" / "s.rec"
        assert rec.path == moved and str(moved) in err
        whole = read_recording(moved)
        assert whole.complete and len(whole) == 400
        cut = read_recording(disk / "s.rec")  # the first part stays where it was, said to be cut
        assert not cut.complete and cut.cut
        assert cut.hashes == whole.hashes[: len(cut)]


def test_a_full_disk_everywhere_stops_the_recording_with_one_line_and_the_session_plays_on(
    make_app, tmp_path, capsys, monkeypatch
):
    from tests.faults import full_disk

    with full_disk(tmp_path / "disk", free=8192) as disk:
        monkeypatch.setenv("XDG_DATA_HOME", str(disk / "data"))  # the recovery folder is on the full disk too
        rec, app = _record_400_steps(make_app, disk / "s.rec")
        assert app.world.frame == 400 and rec.failed and 0 < rec.frames < 400
        err = capsys.readouterr().err
        assert err.count("stopped after") == 1 and "Traceback" not in err and len(err.strip().splitlines()) == 1
        r = read_recording(disk / "s.rec")
        assert not r.complete and len(r) <= rec.frames


def test_size_per_minute(make_app, tmp_path):
    """The figures quoted in input/recording.py's docstring (60 steps/s)."""
    per_min = {}
    path = tmp_path / "phone.rec"
    record_session(make_app, path, steps=600)
    per_min["phone"] = (path.stat().st_size - 100) / 600 * 3600
    src = Fed("m")
    app = make_app(InputHub([src]))
    path = tmp_path / "mouse.rec"
    rec = Recorder(path, RecordingHeader(game="t", seed=7, dt=app.world.dt)).attach(app)
    for i in range(600):
        d = np.array([np.sin(i / 50), -0.3, 1.0])
        src.push(
            PoseSample(
                time=i / 60,
                source="mouse",
                orientation=quat.between([0, 0, 1], d / np.linalg.norm(d)),
                position=[0, 1.5, -4],
                mode="world",
                plane_normal=[0, 0, 1],
                touch=i > 30,
            )
        )
        app.step()
    rec.close()
    per_min["mouse"] = (path.stat().st_size - 100) / 600 * 3600
    assert 400_000 < per_min["phone"] < 800_000 and 400_000 < per_min["mouse"] < 700_000


def test_replay_source_serves_by_index(make_app, tmp_path):
    path = tmp_path / "s.rec"
    record_session(make_app, path, steps=5)
    src = ReplaySource(path)
    assert src.last_frame == 4 and src.frame_at(2).frame == 2 and src.frame_at(5) is None
    assert src.status().packets == 1


def _with_header(path, header: bytes):
    import struct
    import zlib

    path.write_bytes(MAGIC + struct.pack("<II", len(header), zlib.crc32(header)) + header)
    return path


@pytest.mark.parametrize(
    "header,says",
    [
        (b'{"game": "snowman", "seed": 0, "dt": 0.0166, "format": "1"}', "format"),
        (b'{"game": "snowman", "seed": 0, "dt": "fast"}', "dt"),
        (b'{"game": "snowman", "seed": 0, "dt": 1e308}', "dt"),
        (b'{"game": "snowman", "seed": 0, "dt": 0}', "dt"),
        (b'{"game": "snowman", "seed": -1, "dt": 0.0166}', "seed"),
        (b'{"game": "snowman", "seed": true, "dt": 0.0166}', "seed"),
        (b'{"game": ["snowman"], "seed": 0, "dt": 0.0166}', "game"),
        (b'{"game": "snowman", "seed": 0, "dt": 0.0166, "extra": []}', "extra"),
        (b'{"game": "snowman", "seed": 0, "dt": 0.0166, "sources": "osc"}', "sources"),
        (b'{"game": "snowman", "seed": 0, "dt": 0.0166, "hack": 1}', "unknown"),
        (b'{"seed": 0, "dt": 0.0166}', "missing game"),
        (b"[1, 2]", "object"),
        (b"[" * 100_000 + b"]" * 100_000, "unreadable"),
    ],
)
def test_wrong_typed_or_absurd_header_fields_are_a_recording_error(tmp_path, header, says):
    with pytest.raises(RecordingError, match=says):
        read_recording(_with_header(tmp_path / "h.rec", header))


def test_devices_pipes_and_huge_header_claims_are_refused_without_reading(tmp_path):
    import os
    import struct

    with pytest.raises(RecordingError, match="not a regular file"):
        read_recording("/dev/zero")
    fifo = tmp_path / "p.rec"
    os.mkfifo(fifo)
    with pytest.raises(RecordingError, match="not a regular file"):
        read_recording(fifo)  # opening must not wait for a writer
    big = tmp_path / "big.rec"
    big.write_bytes(MAGIC + struct.pack("<II", 2**32 - 1, 0))
    with pytest.raises(RecordingError, match="claims"):
        read_recording(big)


def test_a_growing_recording_is_fsynced_every_second_and_at_its_close(make_app, tmp_path, monkeypatch):
    """At most a second of play is in the OS's cache alone when the power goes (broken on purpose:
    without the periodic fsync only the close synced, 1 call for 150 records)."""
    import os

    from input.recording import FSYNC_EVERY

    synced: list[int] = []
    real = os.fsync
    monkeypatch.setattr(os, "fsync", lambda fd: (synced.append(fd), real(fd))[1])
    src = Fed("m")
    app = make_app(InputHub([src]))
    rec = Recorder(tmp_path / "s.rec", RecordingHeader(game="t", seed=7, dt=app.world.dt)).attach(app)
    app.run_steps(150)
    assert len(synced) == 150 // FSYNC_EVERY == 2
    rec.close()
    assert len(synced) == 3 and read_recording(tmp_path / "s.rec").complete
