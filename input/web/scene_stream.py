"""The phone's view of the scene: quantised snapshots and the delta-coded frames between them.

The page draws what the desktop draws: the primitives a game's drawing puts in a
:class:`~engine.render.scene.RenderScene` (puppet bones as capsules, snowballs and
snowmen as spheres, props as boxes, the stick as a line and a point). Sending these
rather than joint transforms keeps one drawing per game: the page needs no copy of
each game's rules for snowmen, sticks or height cues, and the phone's picture is the
desktop's picture.

A :class:`SceneState` is one step's primitives quantised to ``int16`` per column
(positions and sizes in millimetres, colours in 1/255, rotations in 1/32767). A frame
(:func:`encode_frame`) carries what changed since the state the *same phone* last got:
per kind, a bit per row that changed and a bit per column that changed in any of them,
then those columns of those rows, as ``int8`` differences when every difference fits (a
walking puppet moves a few centimetres a step), else as ``int16`` values. A row that did
not move costs one bit, a colour that did not change nothing. Frame layout (little-endian)::

    "PF" u8 version u8 flags u32 step f64 published (s since the epoch: latency figures only)
    f32 camera position[3] f32 camera rotation (w,x,y,z)[4] f32 fov_y (degrees)
    per kind in KINDS: u16 rows, u8 mode (0 unchanged, 1 int8 deltas, 2 int16 values)
                       [mode > 0: u16 changed-column bits, ceil(rows/8) bytes of changed-row
                        bits, then the changed columns of the changed rows, row by row]

:func:`decode_frame` is the reader the tests and the bench use; ``page/stream.js``
is the page's.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from engine.errors import FormatError
from engine.render.scene import RenderScene

__all__ = ["SceneState", "CameraPose", "KINDS", "SCALES", "quantise", "encode_frame", "decode_frame",
           "FrameError", "FRAME_VERSION"]

FRAME_VERSION = 1
_MM, _C, _Q = 1000.0, 255.0, 32767.0
#: Per kind, the scale of each column of the scene's rows (value × scale, rounded, is sent).
SCALES: dict[str, tuple[float, ...]] = {
    "capsules": (_MM,) * 7 + (_C,) * 3 + (1.0,),          # a[3] b[3] radius colour[3] outline
    "spheres": (_MM,) * 7 + (_C,) * 3 + (1.0,),           # centre twice, radius, colour, outline
    "boxes": (_MM,) * 6 + (_Q,) * 4 + (_C,) * 3 + (1.0,),  # centre, half extents, rotation, colour, outline
    "lines": (_MM,) * 6 + (_C,) * 3 + (10.0,),            # p0, p1, colour, width (1/10 px)
    "points": (_MM,) * 4 + (_C,) * 3 + (1.0,),            # position, size, colour, size-in-pixels flag
}
KINDS = tuple(SCALES)
_HEADER = struct.Struct("<2sBBId3f4ff")
_KIND = struct.Struct("<HB")
_COLUMNS = struct.Struct("<H")


class FrameError(FormatError):
    """Bytes that are not a scene frame of this version."""


@dataclass(frozen=True)
class CameraPose:
    """Where the phone looks from: eye ``position``, ``rotation`` (w,x,y,z, camera → world), ``fov_y``."""

    position: tuple[float, float, float]
    rotation: tuple[float, float, float, float]
    fov_y: float


@dataclass(frozen=True)
class SceneState:
    """One step's quantised primitives (``rows[kind]``: ``int16 [n, columns]``) and the camera."""

    step: int
    published: float
    camera: CameraPose
    rows: dict[str, NDArray[np.int16]]

    @staticmethod
    def empty() -> SceneState:
        """The state a phone has before its first frame: no rows."""
        return SceneState(-1, 0.0, CameraPose((0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0), 60.0),
                          {k: np.zeros((0, len(s)), dtype=np.int16) for k, s in SCALES.items()})


def quantise(scene: RenderScene, step: int, published: float, camera: CameraPose) -> SceneState:
    """The scene's primitives as a :class:`SceneState` (values beyond ``int16`` are clamped)."""
    rows = {}
    for kind, scales in SCALES.items():
        data = getattr(scene, kind).data.astype(np.float64) * np.asarray(scales)
        rows[kind] = np.clip(np.rint(data), -32767, 32767).astype(np.int16)
    return SceneState(step, published, camera, rows)


def encode_frame(base: SceneState, state: SceneState) -> bytes:
    """The bytes that take a phone holding ``base`` to ``state``."""
    cam = state.camera
    out = [_HEADER.pack(b"PF", FRAME_VERSION, 0, state.step & 0xFFFFFFFF, state.published, *cam.position,
                        *cam.rotation, cam.fov_y)]
    for kind in KINDS:
        new, old = state.rows[kind], base.rows[kind]
        n = len(new)
        if n > 0xFFFF:
            raise ValueError(f"{n} {kind} do not fit in a frame")
        prev = np.zeros_like(new)
        keep = min(n, len(old))
        prev[:keep] = old[:keep]
        changed = np.ones(n, dtype=bool)
        changed[:keep] = np.any(new[:keep] != old[:keep], axis=1)
        if not changed.any():
            out.append(_KIND.pack(n, 0))
            continue
        delta = new[changed].astype(np.int32) - prev[changed]
        columns = np.any(delta != 0, axis=0)
        columns[0] |= not columns.any()  # new rows of zeros: still say which rows they are
        delta = delta[:, columns]
        small = bool(np.all((delta >= -127) & (delta <= 127)))
        out.append(_KIND.pack(n, 1 if small else 2))
        out.append(_COLUMNS.pack(sum(1 << int(c) for c in np.nonzero(columns)[0])))
        out.append(np.packbits(changed, bitorder="little").tobytes())
        out.append(delta.astype("<i1").tobytes() if small else new[changed][:, columns].astype("<i2").tobytes())
    return b"".join(out)


def decode_frame(base: SceneState, data: bytes) -> SceneState:
    """The state a phone holding ``base`` has after ``data`` (the page does the same in ``stream.js``).

    Raises:
        FrameError: wrong magic or version, or the bytes end early or run on.
    """
    if len(data) < _HEADER.size:
        raise FrameError("frame shorter than its header")
    magic, version, _flags, step, published, *cam = _HEADER.unpack_from(data)
    if magic != b"PF" or version != FRAME_VERSION:
        raise FrameError(f"not a version {FRAME_VERSION} scene frame")
    at = _HEADER.size
    rows = {}
    for kind, scales in SCALES.items():
        if at + _KIND.size > len(data):
            raise FrameError(f"frame ends before its {kind}")
        n, mode = _KIND.unpack_from(data, at)
        at += _KIND.size
        old = base.rows[kind]
        new = np.zeros((n, len(scales)), dtype=np.int16)
        keep = min(n, len(old))
        new[:keep] = old[:keep]
        if mode:
            mask_len = (n + 7) // 8
            if at + _COLUMNS.size + mask_len > len(data):
                raise FrameError(f"frame ends inside its {kind}")
            (bits,) = _COLUMNS.unpack_from(data, at)
            columns = np.array([(bits >> c) & 1 for c in range(len(scales))], dtype=bool)
            at += _COLUMNS.size
            changed = np.unpackbits(np.frombuffer(data, np.uint8, mask_len, at), count=n, bitorder="little").astype(bool)
            at += mask_len
            count = int(changed.sum()) * int(columns.sum())
            width = 1 if mode == 1 else 2
            if at + count * width > len(data):
                raise FrameError(f"frame ends inside its {kind}")
            values = np.frombuffer(data, "<i1" if mode == 1 else "<i2", count, at).reshape(-1, int(columns.sum()))
            at += count * width
            rows_changed = new[changed]
            if mode == 1:
                rows_changed[:, columns] = rows_changed[:, columns].astype(np.int32) + values
            else:
                rows_changed[:, columns] = values
            new[changed] = rows_changed
        rows[kind] = new
    if at != len(data):
        raise FrameError("bytes after the last kind")
    pose = CameraPose(tuple(cam[0:3]), tuple(cam[3:7]), cam[7])  # lengths are fixed above
    return SceneState(step, published, pose, rows)
