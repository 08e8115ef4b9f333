"""A recording whose writes fail, without a real full disk: ``os.fsync`` is made to fail once.

The slow tmpfs tests in ``test_recording.py`` show the same on a real full disk; these run in
milliseconds so the mutation run can use them (docs/mutation.md). Broken on purpose by mutation:
the "only N of its M bytes" reason replaced by ``None`` fails
``test_a_recording_cut_under_the_recorder_stops_and_says_why``; a periodic fsync at the 59th record
fails ``test_a_failed_write_goes_on_in_the_recovery_folder_whole``.
"""

from __future__ import annotations

import errno
import os
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from input.recording import FSYNC_EVERY, Recorder, RecordingHeader, read_recording
from input.sample import InputFrame, PoseSample

HASH = "00112233445566778899aabbccddeeff"


def frame(i: int) -> InputFrame:
    return InputFrame(frame=i, samples=(PoseSample(time=i / 60, source="osc:1", orientation=np.array([1.0, 0, 0, 0])),))


def fail_fsync_once(monkeypatch: pytest.MonkeyPatch, calls: list[int]) -> None:
    """The next ``os.fsync`` fails as a full disk does; later ones work."""
    real: Callable[[int], None] = os.fsync

    def fsync(fd: int) -> None:
        calls.append(fd)
        if len(calls) == 1:
            raise OSError(errno.ENOSPC, "No space left on device")
        real(fd)

    monkeypatch.setattr(os, "fsync", fsync)


@pytest.fixture
def recovered(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))
    return tmp_path / "data" / "puppetphone" / "recovered"


def test_a_failed_write_goes_on_in_the_recovery_folder_whole(
    tmp_path: Path, recovered: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    rec = Recorder(tmp_path / "s.rec", RecordingHeader(game="t", seed=1, dt=0.02))
    for i in range(FSYNC_EVERY - 1):
        rec.write(frame(i), HASH, {"A": b"\x00\x01"})
    calls: list[int] = []
    fail_fsync_once(monkeypatch, calls)
    rec.write(frame(FSYNC_EVERY - 1), HASH, {"A": b"\x00\x01"})  # the 60th record is synced: that fails
    assert calls and rec.path == recovered / "s.rec" and not rec.failed and rec.frames == FSYNC_EVERY
    err = capsys.readouterr().err
    assert err == (
        f"recording {tmp_path / 's.rec'}: No space left on device after {FSYNC_EVERY - 1} frames; "
        f"it goes on in {recovered / 's.rec'} (replay that file)\n"
    )
    for i in range(FSYNC_EVERY, FSYNC_EVERY + 5):
        rec.write(frame(i), HASH, {"A": b"\x00\x01"})
    rec.close()
    whole = read_recording(recovered / "s.rec")
    assert whole.complete and [f.frame for f in whole.frames] == list(range(FSYNC_EVERY + 5))
    assert whole.parts == [{"A": b"\x00\x01"}] * (FSYNC_EVERY + 5)
    assert rec.bytes + 8 == (recovered / "s.rec").stat().st_size


def test_an_earlier_recovered_file_is_not_overwritten(
    tmp_path: Path, recovered: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    recovered.mkdir(parents=True)
    (recovered / "s.rec").write_bytes(b"an earlier session")
    rec = Recorder(tmp_path / "s.rec", RecordingHeader(game="t", seed=1, dt=0.02))
    for i in range(FSYNC_EVERY - 1):
        rec.write(frame(i), HASH)
    fail_fsync_once(monkeypatch, [])
    rec.write(frame(FSYNC_EVERY - 1), HASH)
    assert rec.path == recovered / "s.1.rec" and (recovered / "s.rec").read_bytes() == b"an earlier session"
    rec.close()
    assert read_recording(recovered / "s.1.rec").complete


def test_a_recording_cut_under_the_recorder_stops_and_says_why(
    tmp_path: Path, recovered: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "s.rec"
    rec = Recorder(path, RecordingHeader(game="t", seed=1, dt=0.02))
    for i in range(FSYNC_EVERY - 1):
        rec.write(frame(i), HASH)
    expected = rec.bytes
    path.unlink()  # something else replaced the file: what is on disk now cannot be copied whole
    path.write_bytes(b"0123456789")
    fail_fsync_once(monkeypatch, [])
    rec.write(frame(FSYNC_EVERY - 1), HASH)
    assert rec.failed == (
        f"recording {path} stopped after {FSYNC_EVERY - 1} frames: No space left on device "
        f"(and not in {recovered} either: only 10 of its {expected} bytes can be read back)"
    )
    assert capsys.readouterr().err == rec.failed + "\n"
    assert rec.frames == FSYNC_EVERY - 1 and not (recovered / "s.rec").exists()
    rec.write(frame(FSYNC_EVERY), HASH)  # the session plays on: writes are ignored, not raised
    rec.close()
    assert rec.frames == FSYNC_EVERY - 1 and path.stat().st_size == 10


def test_a_failing_sync_at_the_close_says_the_recording_may_be_incomplete(
    tmp_path: Path, recovered: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "s.rec"
    rec = Recorder(path, RecordingHeader(game="t", seed=1, dt=0.02))
    rec.write(frame(0), HASH)
    fail_fsync_once(monkeypatch, [])
    rec.close()
    assert rec.failed == f"recording {path} may be incomplete: No space left on device"
    assert capsys.readouterr().err == rec.failed + "\n"
    assert read_recording(path).complete  # the closing record was written; only its sync failed
    rec.close()  # closed: nothing more happens
    assert capsys.readouterr().err == ""


def test_a_failure_without_an_error_code_is_still_named(
    tmp_path: Path, recovered: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    rec = Recorder(tmp_path / "s.rec", RecordingHeader(game="t", seed=1, dt=0.02))
    for i in range(FSYNC_EVERY - 1):
        rec.write(frame(i), HASH)
    real = os.fsync
    calls: list[int] = []

    def fsync(fd: int) -> None:
        calls.append(fd)
        if len(calls) == 1:
            raise OSError("the device went away")
        real(fd)

    monkeypatch.setattr(os, "fsync", fsync)
    rec.write(frame(FSYNC_EVERY - 1), HASH)
    assert ": the device went away after 59 frames; it goes on in" in capsys.readouterr().err
    rec.close()
