"""HID parsers on report bytes built from the documented layouts; unplug and replug with a fake device."""

from __future__ import annotations

import struct
import threading
import time

import numpy as np
import pytest

from engine import quat
from input.hid import HidSource, ImuIntegrator, SpaceMouseIntegrator, enumerate_supported
from input.hid_reports import (
    DS4_DEFAULT,
    HidFormatError,
    ds4_calibration,
    dualsense_calibration,
    known_device,
    parse_ds4,
    parse_dualsense,
    parse_spacemouse,
)
from input.sample import CONNECT, DISCONNECT, PoseSample


def sm_report(rid, *vals):
    return bytes([rid]) + struct.pack(f"<{len(vals)}h", *vals)


def test_spacemouse_both_layouts():
    split_t = parse_spacemouse(sm_report(1, 350, -175, 0))
    assert np.allclose(split_t.translation, [1, -0.5, 0]) and split_t.rotation is None
    split_r = parse_spacemouse(sm_report(2, 0, 70, -350))
    assert np.allclose(split_r.rotation, [0, 0.2, -1]) and split_r.translation is None
    combined = parse_spacemouse(sm_report(1, 0, 0, 35, 350, 0, 0))
    assert np.allclose(combined.translation, [0, 0, 0.1]) and np.allclose(combined.rotation, [1, 0, 0])
    assert parse_spacemouse(bytes([3, 0b01, 0])).buttons == 1
    assert parse_spacemouse(bytes([0x17, 80])).translation is None  # battery: ignored
    with pytest.raises(HidFormatError):
        parse_spacemouse(bytes([1, 2, 3]))


def test_spacemouse_integration_dead_zone_and_axes():
    sm = SpaceMouseIntegrator(dead_zone=0.1, speed=1.0, turn_rate=1.0)
    sm.update(sm_report(1, 20, 20, 20), 0.01)  # inside the dead zone: nothing moves
    for _ in range(10):
        sm.update(sm_report(1, 0, 0, -350), 0.01)  # pull the cap up (raw Z is down)
    assert np.allclose(sm.position, [0, 0.1, 0]) and np.allclose(sm.orientation, [1, 0, 0, 0])
    for _ in range(10):
        sm.update(sm_report(2, 0, 0, -350), 0.05)  # twist: turns about the vertical
    axis, angle = quat.to_axis_angle(sm.orientation)
    assert np.isclose(angle, 0.5) and np.allclose(np.abs(axis), [0, 1, 0])


def ds4_usb(gyro, accel, ts=0, cross=False):
    r = bytearray(64)
    r[0] = 0x01
    r[5] = 0x08 | (0x20 if cross else 0)
    struct.pack_into("<H", r, 10, ts)
    struct.pack_into("<3h", r, 13, *gyro)
    struct.pack_into("<3h", r, 19, *accel)
    return bytes(r)


def test_ds4_usb_and_bluetooth_layouts():
    r = parse_ds4(ds4_usb((16, -32, 48), (0, 8192, 0), ts=300, cross=True))
    assert np.allclose(r.gyro, [16, -32, 48]) and np.allclose(r.accel, [0, 8192, 0]) and r.cross
    assert np.isclose(r.timestamp, 300 * 16 / 3 * 1e-6) and not r.bluetooth
    bt = bytes([0x11, 0xC0, 0x00]) + ds4_usb((1, 2, 3), (4, 5, 6))[1:] + bytes(12)  # state packet two bytes on
    assert len(bt) == 78
    r = parse_ds4(bt)
    assert np.allclose(r.gyro, [1, 2, 3]) and np.allclose(r.accel, [4, 5, 6]) and r.bluetooth
    with pytest.raises(HidFormatError, match="without HID data"):
        parse_ds4(bytes([0x11, 0x00]) + bytes(76))
    with pytest.raises(HidFormatError):
        parse_ds4(bytes(10))


def test_dualsense_usb_and_bluetooth_layouts():
    r = bytearray(64)
    r[0] = 0x01
    r[8] = 0x28
    struct.pack_into("<3h", r, 16, 100, 0, -100)
    struct.pack_into("<3h", r, 22, 0, 8192, 0)
    struct.pack_into("<I", r, 28, 3_000_000)
    p = parse_dualsense(bytes(r))
    assert np.allclose(p.gyro, [100, 0, -100]) and p.cross and np.isclose(p.timestamp, 1.0)
    bt = bytes([0x31, 0x00]) + bytes(r[1:]) + bytes(13)  # struct one byte on
    assert len(bt) == 78
    p = parse_dualsense(bt)
    assert np.allclose(p.accel, [0, 8192, 0]) and p.bluetooth


def feature(vals, rid):
    return bytes([rid]) + struct.pack("<17h", *vals) + bytes(4)


def test_calibration_formulas():
    # bias 10, ±8192 raw for ±(540+540)/2 °/s speed span; accel ±8192 = ±1 g.
    usb = [10, 10, 10, 8202, -8182, 8202, -8182, 8202, -8182, 540, 540, 8192, -8192, 8192, -8192, 8192, -8192]
    c = ds4_calibration(feature(usb, 0x02))
    gyro, acc = c.apply(np.array([8202.0, 10, 10]), np.array([0.0, 8192, -4096]))
    assert np.allclose(np.degrees(gyro), [540 * 8192 * 2 / (8192 * 2) * 1.0, 0, 0], rtol=1e-6)
    assert np.allclose(acc, [0, 1, -0.5])
    d = dualsense_calibration(feature(usb, 0x05))
    assert np.allclose(d.gyro_scale, 1080 / 16384) and np.allclose(d.accel_bias, 0)
    bad = list(usb)
    bad[0] = 5000
    with pytest.raises(HidFormatError):
        ds4_calibration(feature(bad, 0x02))
    with pytest.raises(HidFormatError):
        ds4_calibration(bytes(10))


def test_imu_integration_turns_and_gravity_holds_the_tilt():
    imu = ImuIntegrator(DS4_DEFAULT, gain=0.05)
    wrap = 65536 * 16 / 3 * 1e-6
    yaw_rate = int(round(90 * 16))  # 90 °/s about Y (yaw) at 1/16 °/s per LSB
    ticks_per_ms = 3 / 16 * 1000
    for i in range(201):  # 1 s at 5 ms, timestamp wrapping on the way
        imu.update(parse_ds4(ds4_usb((0, yaw_rate, 0), (0, 8192, 0), ts=int(i * 5 * ticks_per_ms) % 65536)), wrap)
    axis, angle = quat.to_axis_angle(imu.orientation)
    assert np.isclose(angle, np.pi / 2, atol=0.02) and np.allclose(axis, [0, 1, 0], atol=1e-3)
    # Stick points away from the player (−Z) before turning: after +90° yaw it points to −X.
    assert np.allclose(quat.rotate(imu.stick_orientation(), [0, 0, 1]), [-1, 0, 0], atol=0.03)


def test_known_devices_and_enumerate_filter():
    assert known_device(0x256F, 0xC635) == ("spacemouse", "SpaceMouse Compact")
    assert known_device(0x054C, 0x0CE6)[0] == "dualsense" and known_device(0x054C, 0x09CC)[0] == "ds4"
    assert known_device(0x1234, 0x5678) is None
    devs = enumerate_supported(
        lambda: [
            {"vendor_id": 0x046D, "product_id": 0xC626, "path": b"x"},
            {"vendor_id": 0x046D, "product_id": 0xC077, "path": b"y"},
        ]
    )
    assert [d["name"] for d in devs] == ["SpaceNavigator"]


class FakeSpaceMouse:
    """Yields a few reports, then fails like an unplugged hidraw device."""

    def __init__(self, reports):
        self.reports = list(reports)

    def read(self, n, timeout_ms):
        if not self.reports:
            raise OSError("read error (device disconnected)")
        time.sleep(0.002)
        return list(self.reports.pop(0))

    def close(self):
        pass


def test_unplug_releases_and_replug_reconnects():
    plugged = threading.Event()
    plugged.set()
    opens = []

    def opener():
        if not plugged.is_set():
            raise OSError("no such device")
        opens.append(1)
        if len(opens) == 1:
            plugged.clear()  # this session ends in an unplug; the next open fails until replugged
        return FakeSpaceMouse([sm_report(3, 1), sm_report(1, 0, 0, -350), sm_report(2, 0, 0, 0)])

    src = HidSource(vid=0x046D, pid=0xC626, retry=0.02, opener=opener)
    src.start()
    try:
        end = time.monotonic() + 5
        while time.monotonic() < end and src.status().last_error == "":
            time.sleep(0.01)
        time.sleep(0.1)
        plugged.set()
        while time.monotonic() < end and len(opens) < 2:
            time.sleep(0.01)
        time.sleep(0.05)
    finally:
        src.stop()
    items = src.drain()
    events = [i[0] for i in items if not isinstance(i, PoseSample)]
    samples = [i for i in items if isinstance(i, PoseSample)]
    assert events[:3] == [CONNECT, DISCONNECT, CONNECT] and len(opens) >= 2
    assert samples[0].source == "hid:046d:c626" and samples[0].touch is True
    assert samples[1].position[1] > 0  # pulling the cap up raised the pivot
