"""Serial IMUs: the line formats and teapot packets, through loop:// and a socat pty pair with a cable pull."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import time

import numpy as np
import pytest
import serial

from input.phone_frames import phone_to_stick
from input.sample import CONNECT, DISCONNECT, PoseSample
from input.serial_parse import SerialStreamParser, decode_teapot, parse_line
from input.serial_source import SerialSource


def teapot(q, counter=0):
    out = b"$\x02"
    for v in q:
        i = int(round(v * 16384)) & 0xFFFF
        out += bytes([i >> 8, i & 0xFF])
    return out + bytes([0, counter]) + b"\r\n"


@pytest.mark.parametrize(
    "line,q,pos,touch",
    [
        ("quat\t0.7071\t0.7071\t0\t0\r", (0.7071, 0.7071, 0, 0), None, None),
        ("Quaternion: 1.0000, 0.0000, 0.0000, 0.0000", (1, 0, 0, 0), None, None),
        ("1,0,0,0", (1, 0, 0, 0), None, None),
        ("0.5 0.5 0.5 0.5 1", (0.5, 0.5, 0.5, 0.5), None, True),
        ("1,0,0,0,0.1,0.2,0.3", (1, 0, 0, 0), (0.1, 0.2, 0.3), None),
        ("1,0,0,0,0.1,0.2,0.3,0", (1, 0, 0, 0), (0.1, 0.2, 0.3), False),
    ],
)
def test_line_formats(line, q, pos, touch):
    r = parse_line(line)
    assert np.allclose(r.quaternion, np.array(q) / np.linalg.norm(q)) and r.touch == touch
    assert (r.position is None and pos is None) or np.allclose(r.position, pos)


def test_teapot_decode_negative_components():
    r = decode_teapot(teapot([0.5, -0.5, 0.5, -0.5], 9))
    assert np.allclose(r.quaternion, [0.5, -0.5, 0.5, -0.5])


def test_stream_skips_banners_garbage_and_survives_any_chunking():
    data = (
        b"Initializing I2C devices...\r\nDMP ready! Waiting for first interrupt...\r\n"
        b"Orientation: 359.00, 1.00, 2.00\r\nquat\t1\t0\t0\t0\r\n\xff\xfe\x00"
        + teapot([0, 1, 0, 0], 1)
        + b"Calibration: 3, 3, 3, 3\r\nquat\tnan\t0\t0\t0\r\n2,0,0,0\r\n"
        + teapot([0, 0, 1, 0], 2)
        + b"Quaternion: 0.0, 0.0, 0.0, 1.0\r\n"
    )
    expect = [(1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0), (0, 0, 0, 1)]
    for size in (1, 3, 7, 64, len(data)):
        p = SerialStreamParser()
        out = []
        for i in range(0, len(data), size):
            out += p.feed(data[i : i + size])
        assert [r.quaternion for r in out] == [tuple(map(float, q)) for q in expect], size
        assert p.skipped["not numeric"] == 2 and p.skipped["non-unit quaternion"] == 1
        assert p.skipped["non-finite value"] == 1 and p.skipped["binary garbage"] == 1


def test_overlong_garbage_without_newline_is_dropped():
    p = SerialStreamParser()
    assert p.feed(b"x" * 1000) == [] and p.skipped == {"overlong line": 1}
    assert p.feed(b"\n1,0,0,0\n")[0].quaternion == (1.0, 0.0, 0.0, 0.0)


def test_finite_but_huge_values_are_skipped_not_read():
    p = SerialStreamParser()
    out = p.feed(b"1,0,0,0,1e308,0,0\n1e308,0,0,0\n1,0,0,0,5000,0,0\n1,0,0,0,0.5,0,0\n")
    assert [r.position for r in out] == [(0.5, 0.0, 0.0)]
    assert p.skipped == {"position out of range": 2, "non-unit quaternion": 1}


def _wait(pred, timeout=5.0):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if pred():
            return True
        time.sleep(0.02)
    return False


def test_loop_url_round_trip():
    src = SerialSource("loop://", wake=False)
    src.start()
    try:
        assert _wait(lambda: src.status().connected)
    finally:
        src.stop()


def _socat(tmp_path):
    """A pty pair: ``imu`` is the device's end, ``host`` the one the game opens."""
    a, b = tmp_path / "imu", tmp_path / "host"
    for p in (a, b):
        p.unlink(missing_ok=True)
    proc = subprocess.Popen(
        ["socat", f"pty,raw,echo=0,link={a}", f"pty,raw,echo=0,link={b}"],
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )
    assert _wait(lambda: a.exists() and b.exists())
    return proc, str(a), str(b)


@pytest.mark.skipif(shutil.which("socat") is None, reason="socat is not installed")
def test_socat_pty_with_garbage_partial_lines_and_a_pulled_cable(tmp_path):
    proc, imu, host = _socat(tmp_path)
    src = SerialSource(host, retry=0.1)
    src.start()
    try:
        dev = serial.Serial(imu, 115200, timeout=0.1)
        assert _wait(lambda: src.status().connected)
        dev.write(b"Initializing I2C devices...\r\n\x00\x01\xfe")
        dev.write(b"quat\t0.7071068\t0\t0.7071068\t")  # a partial line...
        time.sleep(0.05)
        dev.write(b"0\r\n" + teapot([1, 0, 0, 0]) + b"1,0,0,0,0,0,0,1\r\n")  # ...completed
        assert _wait(lambda: src.status().packets >= 3)
        # Pull the cable: the device side vanishes.
        dev.close()
        os.killpg(proc.pid, signal.SIGTERM)
        proc.wait(5)
        assert _wait(lambda: not src.status().connected)
        # Plug it back in: the same path comes back, the source reconnects by itself.
        proc, imu, host = _socat(tmp_path)
        dev = serial.Serial(imu, 115200, timeout=0.1)
        assert _wait(lambda: src.reconnects >= 1 and src.status().connected)
        time.sleep(0.2)
        dev.write(b"Quaternion: 1.0, 0.0, 0.0, 0.0\r\n")
        assert _wait(lambda: src.status().packets >= 4)
        dev.close()
    finally:
        src.stop()
        os.killpg(proc.pid, signal.SIGTERM)
        proc.wait(5)
    items = src.drain()
    samples = [i for i in items if isinstance(i, PoseSample)]
    events = [i[0] for i in items if not isinstance(i, PoseSample)]
    assert events[:3] == [CONNECT, DISCONNECT, CONNECT]
    assert len(samples) == 4 and samples[2].touch is True and samples[0].source == f"serial:{host}"
    assert np.allclose(samples[1].orientation, phone_to_stick([1.0, 0, 0, 0]))
    assert src.status().drop_reasons.get("binary garbage", 0) + src.status().drop_reasons.get("not numeric", 0) >= 1
