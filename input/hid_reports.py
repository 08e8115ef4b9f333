"""HID report decoding for the 3Dconnexion SpaceMouse family and Sony controllers' IMUs.

Pure functions on the bytes ``hid.device().read()`` returns (report ID in byte 0
for numbered reports), so they are tested on byte strings built from the
documented layouts (input-protocols §2; SDL ``SDL_hidapi_ps4.c``, Linux
``hid-playstation.c``, pyspacemouse, spacenavd).

SpaceMouse: report 1 holds translation (int16 LE ×3); older devices send rotation
in report 2, newer ones in bytes 7–12 of report 1; report 3 is the button bitmap.
Values span ±350.

DualShock 4: USB report 0x01 (gyro bytes 13–18, accel 19–24, u16 timestamp 10–11
in 16/3 µs), Bluetooth 0x11 (each +2). DualSense: USB 0x01 (gyro 16–21, accel
22–27, u32 timestamp 28–31 in 1/3 µs), Bluetooth 0x31 (each +1). Gyro axes are
pitch, yaw, roll; the calibration feature report (0x02/0x05 for the DS4, 0x05 for
the DualSense) gives per-axis bias and scale.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

import numpy as np

from engine.errors import FormatError

__all__ = [
    "SPACEMOUSE_IDS",
    "SPACEMOUSE_COMBINED",
    "SONY_VID",
    "DS4_PIDS",
    "DUALSENSE_PIDS",
    "AXIS_SCALE",
    "SpaceMouseReport",
    "parse_spacemouse",
    "ImuReport",
    "ImuCalibration",
    "parse_ds4",
    "parse_dualsense",
    "ds4_calibration",
    "dualsense_calibration",
    "DS4_DEFAULT",
    "DUALSENSE_DEFAULT",
    "HidFormatError",
    "known_device",
]

from engine.arrays import F64 as F

AXIS_SCALE = 350.0

# (vid, pid) -> name; rotation in report 2 unless listed in SPACEMOUSE_COMBINED.
SPACEMOUSE_IDS: dict[tuple[int, int], str] = {
    (0x046D, 0xC626): "SpaceNavigator",
    (0x046D, 0xC628): "SpaceNavigator for Notebooks",
    (0x046D, 0xC627): "SpaceExplorer",
    (0x046D, 0xC625): "SpacePilot",
    (0x046D, 0xC629): "SpacePilot Pro",
    (0x046D, 0xC62B): "SpaceMouse Pro",
    (0x256F, 0xC635): "SpaceMouse Compact",
    (0x256F, 0xC62E): "SpaceMouse Wireless (cable)",
    (0x256F, 0xC62F): "SpaceMouse Wireless (receiver)",
    (0x256F, 0xC63A): "SpaceMouse Wireless (BT)",
    (0x256F, 0xC631): "SpaceMouse Pro Wireless (cable)",
    (0x256F, 0xC632): "SpaceMouse Pro Wireless (receiver)",
    (0x256F, 0xC638): "SpaceMouse Pro Wireless (BT)",
    (0x256F, 0xC633): "SpaceMouse Enterprise",
    (0x256F, 0xC652): "3Dconnexion Universal Receiver",
}
SPACEMOUSE_COMBINED = frozenset({(0x256F, p) for p in (0xC62E, 0xC62F, 0xC63A, 0xC631, 0xC632, 0xC638, 0xC633, 0xC652)})
SONY_VID = 0x054C
DS4_PIDS = {0x05C4: "DualShock 4", 0x09CC: "DualShock 4 (v2)", 0x0BA0: "DualShock 4 USB dongle"}
DUALSENSE_PIDS = {0x0CE6: "DualSense", 0x0DF2: "DualSense Edge"}


class HidFormatError(FormatError):
    """A report too short or of an unexpected ID for the parser it was given."""


def known_device(vid: int, pid: int) -> tuple[str, str] | None:
    """``(kind, name)`` with kind ``spacemouse``/``ds4``/``dualsense`` for a supported device."""
    if (vid, pid) in SPACEMOUSE_IDS:
        return "spacemouse", SPACEMOUSE_IDS[(vid, pid)]
    if vid == SONY_VID and pid in DS4_PIDS:
        return "ds4", DS4_PIDS[pid]
    if vid == SONY_VID and pid in DUALSENSE_PIDS:
        return "dualsense", DUALSENSE_PIDS[pid]
    return None


def _i16x3(data: bytes, at: int) -> F:
    return np.array(struct.unpack_from("<3h", data, at), dtype=np.float64)


@dataclass(frozen=True)
class SpaceMouseReport:
    """What one report carried, each axis scaled to about ±1 (raw device axes)."""

    translation: F | None = None
    rotation: F | None = None
    buttons: int | None = None


def parse_spacemouse(report: bytes | list[int]) -> SpaceMouseReport:
    """Decode one SpaceMouse report (either layout: report 1 of 7 or 13 bytes, 2, or 3)."""
    data = bytes(report)
    if not data:
        raise HidFormatError("empty report")
    rid = data[0]
    if rid == 1 and len(data) >= 13:
        return SpaceMouseReport(_i16x3(data, 1) / AXIS_SCALE, _i16x3(data, 7) / AXIS_SCALE)
    if rid == 1 and len(data) >= 7:
        return SpaceMouseReport(translation=_i16x3(data, 1) / AXIS_SCALE)
    if rid == 2 and len(data) >= 7:
        return SpaceMouseReport(rotation=_i16x3(data, 1) / AXIS_SCALE)
    if rid == 3 and len(data) >= 2:
        return SpaceMouseReport(buttons=int.from_bytes(data[1:], "little"))
    if rid in (1, 2, 3):
        raise HidFormatError(f"report {rid} too short ({len(data)} bytes)")
    return SpaceMouseReport()  # battery, LED echo …: nothing for the stick


@dataclass(frozen=True)
class ImuCalibration:
    """Per-axis gyro bias (raw) and scale (°/s per LSB), accel bias (raw) and scale (g per LSB)."""

    gyro_bias: F
    gyro_scale: F
    accel_bias: F
    accel_scale: F

    def apply(self, gyro_raw: F, accel_raw: F) -> tuple[F, F]:
        """Gyro in rad/s and accel in g."""
        gyro = np.radians((gyro_raw - self.gyro_bias) * self.gyro_scale)
        return gyro, (accel_raw - self.accel_bias) * self.accel_scale


DS4_DEFAULT = ImuCalibration(np.zeros(3), np.full(3, 1 / 16), np.zeros(3), np.full(3, 1 / 8192))
DUALSENSE_DEFAULT = ImuCalibration(np.zeros(3), np.full(3, 1 / 16), np.zeros(3), np.full(3, 1 / 8192))


@dataclass(frozen=True)
class ImuReport:
    """Raw IMU values of one controller report, its sensor time in seconds and the cross button."""

    gyro: F
    accel: F
    timestamp: float
    cross: bool
    bluetooth: bool


def parse_ds4(report: bytes | list[int]) -> ImuReport:
    """Decode a DualShock 4 input report (USB 0x01 of 64 bytes, or Bluetooth 0x11–0x19)."""
    data = bytes(report)
    if len(data) >= 64 and data[0] == 0x01:
        o = 0
    elif len(data) >= 78 and 0x11 <= data[0] <= 0x19:
        if not data[1] & 0x80:
            raise HidFormatError("Bluetooth report without HID data")
        o = 2
    else:
        raise HidFormatError(f"not a DS4 IMU report (id 0x{data[0] if data else 0:02x}, {len(data)} bytes)")
    ts = struct.unpack_from("<H", data, 10 + o)[0] * 16.0 / 3.0 * 1e-6
    return ImuReport(_i16x3(data, 13 + o), _i16x3(data, 19 + o), ts, bool(data[5 + o] & 0x20), o == 2)


def parse_dualsense(report: bytes | list[int]) -> ImuReport:
    """Decode a DualSense input report (USB 0x01 of 64 bytes, or Bluetooth 0x31 of 78)."""
    data = bytes(report)
    if len(data) >= 64 and data[0] == 0x01:
        o = 0
    elif len(data) >= 78 and data[0] == 0x31:
        o = 1
    else:
        raise HidFormatError(f"not a DualSense IMU report (id 0x{data[0] if data else 0:02x}, {len(data)} bytes)")
    ts = struct.unpack_from("<I", data, 28 + o)[0] / 3.0 * 1e-6
    return ImuReport(_i16x3(data, 16 + o), _i16x3(data, 22 + o), ts, bool(data[8 + o] & 0x20), o == 1)


def _feature(data: bytes) -> dict[str, int]:
    if len(data) < 35:
        raise HidFormatError(f"calibration report too short ({len(data)} bytes)")
    names = [
        "pb",
        "yb",
        "rb",
        "a7",
        "a9",
        "a11",
        "a13",
        "a15",
        "a17",
        "sp",
        "sm",
        "axp",
        "axm",
        "ayp",
        "aym",
        "azp",
        "azm",
    ]
    return dict(zip(names, struct.unpack_from("<17h", data, 1), strict=True))


def _accel(c: dict[str, int]) -> tuple[F, F]:
    plus = np.array([c["axp"], c["ayp"], c["azp"]], dtype=np.float64)
    minus = np.array([c["axm"], c["aym"], c["azm"]], dtype=np.float64)
    span = plus - minus
    if np.any(span == 0):
        raise HidFormatError("accelerometer calibration has a zero range")
    return plus - span / 2.0, 2.0 / span


def ds4_calibration(feature: bytes | list[int], bluetooth: bool = False) -> ImuCalibration:
    """DS4 calibration from feature report 0x02 (USB) or 0x05 (Bluetooth), as SDL computes it."""
    c = _feature(bytes(feature))
    bias = np.array([c["pb"], c["yb"], c["rb"]], dtype=np.float64)
    if bluetooth:  # pitch+, yaw+, roll+, pitch−, yaw−, roll−
        plus = np.array([c["a7"], c["a9"], c["a11"]], dtype=np.float64)
        minus = np.array([c["a13"], c["a15"], c["a17"]], dtype=np.float64)
    else:  # pitch+, pitch−, yaw+, yaw−, roll+, roll−
        plus = np.array([c["a7"], c["a11"], c["a15"]], dtype=np.float64)
        minus = np.array([c["a9"], c["a13"], c["a17"]], dtype=np.float64)
    denom = np.abs(plus - bias) + np.abs(minus - bias)
    if np.any(denom == 0) or np.any(np.abs(bias) > 1024):
        raise HidFormatError("implausible gyro calibration")
    scale = (c["sp"] + c["sm"]) / denom
    if np.any(np.abs(1.0 - scale * 16.0) > 0.5):  # SDL rejects scales far from the nominal 1/16 °/s
        raise HidFormatError("implausible gyro calibration scale")
    ab, asc = _accel(c)
    return ImuCalibration(bias, scale, ab, asc)


def dualsense_calibration(feature: bytes | list[int]) -> ImuCalibration:
    """DualSense calibration from feature report 0x05, as the Linux driver computes it."""
    c = _feature(bytes(feature))
    bias = np.array([c["pb"], c["yb"], c["rb"]], dtype=np.float64)
    plus = np.array([c["a7"], c["a11"], c["a15"]], dtype=np.float64)
    minus = np.array([c["a9"], c["a13"], c["a17"]], dtype=np.float64)
    span = plus - minus
    if np.any(span == 0):
        raise HidFormatError("gyro calibration has a zero range")
    ab, asc = _accel(c)
    return ImuCalibration(bias, (c["sp"] + c["sm"]) / span, ab, asc)
