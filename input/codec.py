"""Binary encoding of :class:`InputFrame` — the payload of every recording record.

Floats are stored as little-endian float64, so decoding gives back the very bits
that were encoded; the hub round-trips every live frame through this codec before
the simulation sees it, which makes a live run and its replay read identical
input by construction.

Layout of one frame (all little-endian)::

    u32 frame  u16 n_samples  sample*  u8 n_events  (u8 kind, str source)*
    sample = str source, f64 time, u16 flags, f64[4] orientation,
             [f64[3] position] [f64[3] angular_velocity] [f64[3] acceleration]
             [f64[3] plane_normal] [f64 depth_delta]
    str    = u8 length, utf-8 bytes

With the record framing and hash (input/recording.py), a step with one mouse sample
takes about 127 bytes and one with a phone sample carrying gyro and acceleration
about 138 bytes.
"""

from __future__ import annotations

import struct
from typing import Any

import numpy as np

from engine.errors import FormatError
from input.sample import EVENT_KINDS, InputFrame, PoseSample, check_sample_ranges

__all__ = ["encode_frame", "decode_frame", "CodecError"]

_F_POS, _F_GYR, _F_ACC, _F_PLANE, _F_DEPTH = 1, 2, 4, 8, 16
_F_HAS_TOUCH, _F_TOUCH, _F_WORLD, _F_FLICK, _F_CAL = 32, 64, 128, 256, 512
_HEAD = struct.Struct("<IH")
_SAMPLE_HEAD = struct.Struct("<dH4d")
_V3 = struct.Struct("<3d")
_D = struct.Struct("<d")


class CodecError(FormatError):
    """A frame's bytes do not decode (truncated, corrupt, or a sample out of range)."""


def _put_str(out: bytearray, s: str) -> None:
    b = s.encode()
    out.append(len(b))
    out += b


def encode_frame(frame: InputFrame) -> bytes:
    """Bytes of one frame (see the module docs for the layout)."""
    out = bytearray(_HEAD.pack(frame.frame, len(frame.samples)))
    for s in frame.samples:
        flags = 0
        extra = bytearray()
        for bit, v in (
            (_F_POS, s.position),
            (_F_GYR, s.angular_velocity),
            (_F_ACC, s.acceleration),
            (_F_PLANE, s.plane_normal),
        ):
            if v is not None:
                flags |= bit
                extra += _V3.pack(*v)
        if s.depth_delta != 0.0:
            flags |= _F_DEPTH
            extra += _D.pack(s.depth_delta)
        if s.touch is not None:
            flags |= _F_HAS_TOUCH | (_F_TOUCH if s.touch else 0)
        flags |= (_F_WORLD if s.mode == "world" else 0) | (_F_FLICK if s.flick else 0) | (_F_CAL if s.calibrate else 0)
        _put_str(out, s.source)
        out += _SAMPLE_HEAD.pack(s.time, flags, *s.orientation)
        out += extra
    out.append(len(frame.events))
    for kind, src in frame.events:
        out.append(EVENT_KINDS.index(kind))
        _put_str(out, src)
    return bytes(out)


class _Reader:
    def __init__(self, data: bytes) -> None:
        self.data, self.pos = memoryview(data), 0

    def take(self, n: int) -> memoryview:
        if self.pos + n > len(self.data):
            raise CodecError(f"frame truncated at byte {self.pos} (needs {n} more)")
        chunk = self.data[self.pos : self.pos + n]
        self.pos += n
        return chunk

    def unpack(self, st: struct.Struct) -> tuple[Any, ...]:
        return st.unpack(self.take(st.size))

    def string(self) -> str:
        n = self.take(1)[0]
        try:
            return bytes(self.take(n)).decode()
        except UnicodeDecodeError as exc:
            raise CodecError(f"bad source id: {exc}") from None


def decode_frame(data: bytes) -> InputFrame:
    """The frame encoded in ``data``; :class:`CodecError` if it is truncated or corrupt."""
    r = _Reader(data)
    index, n = r.unpack(_HEAD)
    samples: list[PoseSample] = []
    for _ in range(n):
        source = r.string()
        t, flags, *q = r.unpack(_SAMPLE_HEAD)
        vecs = {}
        for bit in (_F_POS, _F_GYR, _F_ACC, _F_PLANE):
            vecs[bit] = np.array(r.unpack(_V3)) if flags & bit else None
        depth = r.unpack(_D)[0] if flags & _F_DEPTH else 0.0
        sample = PoseSample.__new__(PoseSample)
        # Bypass __post_init__'s renormalisation: the bits must come back unchanged.
        sample.__dict__.update(
            time=t,
            source=source,
            orientation=np.array(q),
            position=vecs[_F_POS],
            angular_velocity=vecs[_F_GYR],
            acceleration=vecs[_F_ACC],
            touch=bool(flags & _F_TOUCH) if flags & _F_HAS_TOUCH else None,
            mode="world" if flags & _F_WORLD else "device",
            plane_normal=vecs[_F_PLANE],
            depth_delta=depth,
            flick=bool(flags & _F_FLICK),
            calibrate=bool(flags & _F_CAL),
        )
        try:
            check_sample_ranges(sample)
        except ValueError as exc:  # a damaged or hand-made file must not put NaN into the world
            raise CodecError(f"sample {len(samples)} of {source!r}: {exc}") from None
        if not source:
            raise CodecError(f"sample {len(samples)} has an empty source id")
        samples.append(sample)
    events = []
    for _ in range(r.take(1)[0]):
        k = r.take(1)[0]
        if k >= len(EVENT_KINDS):
            raise CodecError(f"unknown event kind {k}")
        events.append((EVENT_KINDS[k], r.string()))
    if r.pos != len(data):
        raise CodecError(f"{len(data) - r.pos} trailing bytes after frame")
    return InputFrame(frame=index, samples=tuple(samples), events=tuple(events))
