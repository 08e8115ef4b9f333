"""Serial IMU stream parsing: the de-facto line formats and the i2cdevlib teapot packet.

There is no standard (input-protocols §3), so the parser accepts what vendor
example sketches print, all quaternions **w,x,y,z**:

- i2cdevlib ``OUTPUT_READABLE_QUATERNION``: ``quat\\tw\\tx\\ty\\tz``;
- Adafruit BNO055 ``webserial_3d``: ``Quaternion: w, x, y, z`` (its ``Orientation:`` and
  ``Calibration:`` lines are skipped);
- plain CSV/whitespace: ``qw,qx,qy,qz[,x,y,z][,touch]``;
- the 14-byte teapot packet ``'$' 0x02 qw qx qy qz (int16 big-endian, /16384) 0x00 counter '\\r' '\\n'``.

Boot banners, garbage bytes, partial lines, non-unit quaternions and positions beyond
``input.sample.LIMITS`` are skipped and counted. :class:`SerialStreamParser` is fed arbitrary chunks (a read may end
mid-line or mid-packet) and yields :class:`ImuReading` values.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from input.sample import LIMITS

__all__ = ["ImuReading", "SerialStreamParser", "parse_line", "decode_teapot", "TEAPOT_LEN"]

TEAPOT_LEN = 14
MAX_LINE = 256
_NUM = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|nan|inf", re.IGNORECASE)
_NOISE = re.compile(rb"^.*[^\t\r\x20-\x7e]", re.DOTALL)
_SKIP_LABELS = ("orientation", "calibration", "ypr", "euler", "areal", "aworld")


@dataclass(frozen=True)
class ImuReading:
    """One parsed reading: quaternion (w,x,y,z), optional position and touch."""

    quaternion: tuple[float, float, float, float]
    position: tuple[float, float, float] | None = None
    touch: bool | None = None


class ParseSkip(Exception):
    """A line or packet that carries no reading; the text says why."""


def _unit(q: list[float]) -> tuple[float, float, float, float]:
    if not all(math.isfinite(v) for v in q):
        raise ParseSkip("non-finite value")
    n = math.sqrt(sum(v * v for v in q))
    if abs(n - 1.0) > 0.05:
        raise ParseSkip(f"non-unit quaternion (norm {n:.3g})")
    return (q[0] / n, q[1] / n, q[2] / n, q[3] / n)


def parse_line(line: str) -> ImuReading:
    """Parse one text line; raises :class:`ParseSkip` for anything that is not a reading."""
    text = line.strip()
    if not text:
        raise ParseSkip("empty line")
    label = ""
    m = re.match(r"^([A-Za-z_][A-Za-z_ ]*?)\s*[:\t]\s*(.*)$", text)
    if m:
        label, text = m.group(1).strip().lower(), m.group(2)
    if label in _SKIP_LABELS:
        raise ParseSkip(f"{label} line")
    if label not in ("", "quat", "quaternion", "q"):
        raise ParseSkip("unknown label")
    fields = [f for f in re.split(r"[,\s;]+", text) if f]
    if not fields or not all(_NUM.fullmatch(f) for f in fields):
        raise ParseSkip("not numeric")
    v = [float(f) for f in fields]
    if label and len(v) != 4:
        raise ParseSkip(f"{len(v)} values after {label!r}")
    if len(v) not in (4, 5, 7, 8):
        raise ParseSkip(f"{len(v)} values")
    q = _unit(v[:4])
    pos = None
    if len(v) >= 7:
        if not all(math.isfinite(x) for x in v[4:7]):
            raise ParseSkip("non-finite value")
        if max(abs(x) for x in v[4:7]) > LIMITS["position"]:
            raise ParseSkip("position out of range")
        pos = (v[4], v[5], v[6])
    touch = bool(v[-1]) if len(v) in (5, 8) else None
    return ImuReading(q, pos, touch)


def decode_teapot(packet: bytes) -> ImuReading:
    """Decode one 14-byte teapot packet (the MPUTeapot sketch's arithmetic)."""
    if len(packet) != TEAPOT_LEN or packet[:2] != b"$\x02" or packet[12:] != b"\r\n":
        raise ParseSkip("not a teapot packet")
    q = []
    for i in range(4):
        v = ((packet[2 + 2 * i] << 8) | packet[3 + 2 * i]) / 16384.0
        q.append(v - 4.0 if v >= 2.0 else v)
    return ImuReading(_unit(q))


class SerialStreamParser:
    """Incremental parser over a byte stream that mixes text lines and teapot packets."""

    def __init__(self) -> None:
        self._buf = bytearray()
        self.skipped: dict[str, int] = {}

    def _skip(self, reason: str) -> None:
        self.skipped[reason] = self.skipped.get(reason, 0) + 1

    def feed(self, chunk: bytes) -> list[ImuReading]:
        """Readings completed by ``chunk`` (a partial line or packet waits for the next chunk)."""
        self._buf += chunk
        out: list[ImuReading] = []
        buf = self._buf
        while buf:
            start, nl = buf.find(b"$\x02"), buf.find(b"\n")
            if start >= 0 and (nl < 0 or start < nl):  # a teapot packet may start here
                if len(buf) < start + TEAPOT_LEN:
                    break
                if buf[start + 12 : start + TEAPOT_LEN] == b"\r\n":
                    if start:
                        self._skip("binary garbage")
                    try:
                        out.append(decode_teapot(bytes(buf[start : start + TEAPOT_LEN])))
                    except ParseSkip as exc:
                        self._skip(str(exc).split(" (")[0])
                    del buf[: start + TEAPOT_LEN]
                    continue
            nl = buf.find(b"\n")
            if nl < 0:
                if len(buf) > MAX_LINE:  # no newline in sight: garbage, drop it
                    self._skip("overlong line")
                    del buf[:]
                break
            raw = bytes(buf[:nl])
            del buf[: nl + 1]
            noise = _NOISE.search(raw)
            if noise is not None:  # line noise before the text (a cable plugged in mid-line): keep the tail
                self._skip("binary garbage")
                raw = raw[noise.end() :]
            try:
                out.append(parse_line(raw.decode("ascii")))
            except ParseSkip as exc:
                self._skip(str(exc).split(" (")[0])
        return out
