"""The phone's view of the scene: quantised snapshots and the delta-coded frames between them.

The page draws what the desktop draws: the primitives a game's drawing puts in a
:class:`~engine.render.scene.RenderScene` (puppet bones as capsules, snowballs and
snowmen as spheres, props as boxes, the stick as a line and a point, conifer tiers as
cones; footprints). Sending these
rather than joint transforms keeps one drawing per game: the page needs no copy of
each game's rules for snowmen, sticks or height cues, and the phone's picture is the
desktop's picture.

A :class:`SceneState` is one step's primitives quantised to ``int16`` per column
(positions and sizes in millimetres, colours in 1/255, rotations in 1/32767), and the
snow's tracks (:class:`MarksGrid`: how much snow each cell lost, in 1/255). A frame
(:func:`encode_frame`) carries what changed since the state the *same phone* last got:
per kind, a bit per row that changed and a bit per column that changed in any of them,
then those columns of those rows, as ``int8`` differences when every difference fits (a
walking puppet moves a few centimetres a step), else as ``int16`` values. A row that did
not move costs one bit, a colour that did not change nothing. The tracks change where a
ball rolls: the cells that changed go as the smaller of the rectangle around them or a
list of (index, value). Frame layout (little-endian)::

    "PF" u8 version u8 flags u32 step f64 published (s since the epoch: latency figures only)
    f32 camera position[3] f32 camera rotation (w,x,y,z)[4] f32 fov_y (degrees)
    per kind in KINDS: u16 rows, u8 mode (0 unchanged, 1 int8 deltas, 2 int16 values)
                       [mode > 0: u16 changed-column bits, ceil(rows/8) bytes of changed-row
                        bits, then the changed columns of the changed rows, row by row]
    tracks: u8 mode (0 none, 1 unchanged, 2 rectangle, 3 list)
            [mode > 1: u16 nx u16 nz f32 x0 f32 z0 f32 cell, then
             2: u16 row0 u16 col0 u16 rows u16 cols, rows × cols u8 values (row-major);
             3: u32 count, count × u32 cell index (row × nx + col), count × u8 values]

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

__all__ = [
    "SceneState",
    "CameraPose",
    "MarksGrid",
    "KINDS",
    "SCALES",
    "quantise",
    "encode_frame",
    "decode_frame",
    "FrameError",
    "FRAME_VERSION",
    "MAX_MARKS_CELLS",
]

FRAME_VERSION = 3
_MM, _C, _Q = 1000.0, 255.0, 32767.0
#: Per kind, the scale of each column of the scene's rows (value × scale, rounded, is sent).
SCALES: dict[str, tuple[float, ...]] = {
    "capsules": (_MM,) * 7 + (_C,) * 3 + (1.0,),  # a[3] b[3] radius colour[3] outline
    "spheres": (_MM,) * 7 + (_C,) * 3 + (1.0,),  # centre twice, radius, colour, outline
    "boxes": (_MM,) * 6 + (_Q,) * 4 + (_C,) * 3 + (1.0,),  # centre, half extents, rotation, colour, outline
    "lines": (_MM,) * 6 + (_C,) * 3 + (10.0,),  # p0, p1, colour, width (1/10 px)
    "points": (_MM,) * 4 + (_C,) * 3 + (1.0,),  # position, size, colour, size-in-pixels flag
    "prints": (_MM,) * 2 + (_Q,) * 2 + (_MM,) * 2 + (_C,),  # footprint: x z, heading cos sin, half sizes, strength
    "cones": (_MM,) * 7 + (_C,) * 4,  # base[3] apex[3] radius colour[3] snow (conifer tiers; static: 3 B a frame)
}
KINDS = tuple(SCALES)
#: The most cells a tracks grid may have (the snowman's is 240 × 240): a reader allocates no more.
MAX_MARKS_CELLS = 1 << 20
_HEADER = struct.Struct("<2sBBId3f4ff")
_KIND = struct.Struct("<HB")
_COLUMNS = struct.Struct("<H")
_GRID = struct.Struct("<HHfff")
_RECT = struct.Struct("<HHHH")
_COUNT = struct.Struct("<I")


class FrameError(FormatError):
    """Bytes that are not a scene frame of this version."""


@dataclass(frozen=True)
class CameraPose:
    """Where the phone looks from: eye ``position``, ``rotation`` (w,x,y,z, camera → world), ``fov_y``."""

    position: tuple[float, float, float]
    rotation: tuple[float, float, float, float]
    fov_y: float


@dataclass(frozen=True)
class MarksGrid:
    """The tracks in the snow, quantised: ``cells [nz, nx]`` (``uint8``, 255: all the snow gone), row ``k``
    at ``z0 + (k + 0.5)·cell`` as in :class:`~engine.render.scene.GroundMarks`."""

    cells: NDArray[np.uint8]
    x0: float
    z0: float
    cell: float

    def same_grid(self, other: MarksGrid | None) -> bool:
        """Whether ``other`` covers the same cells (so only values need sending)."""
        return (
            other is not None
            and other.cells.shape == self.cells.shape
            and (other.x0, other.z0, other.cell) == (self.x0, self.z0, self.cell)
        )


@dataclass(frozen=True)
class SceneState:
    """One step's quantised primitives (``rows[kind]``: ``int16 [n, columns]``), tracks and camera."""

    step: int
    published: float
    camera: CameraPose
    rows: dict[str, NDArray[np.int16]]
    marks: MarksGrid | None = None

    @staticmethod
    def empty() -> SceneState:
        """The state a phone has before its first frame: no rows."""
        return SceneState(
            -1,
            0.0,
            CameraPose((0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0), 60.0),
            {k: np.zeros((0, len(s)), dtype=np.int16) for k, s in SCALES.items()},
        )


def quantise(scene: RenderScene, step: int, published: float, camera: CameraPose) -> SceneState:
    """The scene's primitives and tracks as a :class:`SceneState` (values beyond ``int16`` are clamped)."""
    rows = {}
    for kind, scales in SCALES.items():
        data = getattr(scene, kind).data.astype(np.float64) * np.asarray(scales)
        rows[kind] = np.clip(np.rint(data), -32767, 32767).astype(np.int16)
    marks = None
    if scene.marks is not None:
        m = scene.marks
        x0, z0, cell = (float(np.float32(v)) for v in (m.x0, m.z0, m.cell))  # as the frame's f32 carry them
        marks = MarksGrid(np.rint(m.amount * 255.0).astype(np.uint8), x0, z0, cell)
    return SceneState(step, published, camera, rows, marks)


def _encode_marks(base: MarksGrid | None, marks: MarksGrid | None) -> bytes:
    """The tracks' part of a frame: the cells that differ from ``base`` (see the module docstring)."""
    if marks is None:
        return b"\0"
    if marks.same_grid(base):
        assert base is not None
        changed = marks.cells != base.cells
        if not changed.any():
            return b"\1"
    else:
        changed = np.ones(marks.cells.shape, dtype=bool)
    nz, nx = marks.cells.shape
    if nx * nz > MAX_MARKS_CELLS:
        raise ValueError(f"a tracks grid of {nx} × {nz} cells does not fit in a frame")
    head = _GRID.pack(nx, nz, marks.x0, marks.z0, marks.cell)
    rows, cols = np.nonzero(changed.any(axis=1))[0], np.nonzero(changed.any(axis=0))[0]
    r0, r1, c0, c1 = int(rows[0]), int(rows[-1]) + 1, int(cols[0]), int(cols[-1]) + 1
    flat = np.flatnonzero(changed)
    if (r1 - r0) * (c1 - c0) <= 5 * len(flat):
        return b"\2" + head + _RECT.pack(r0, c0, r1 - r0, c1 - c0) + marks.cells[r0:r1, c0:c1].tobytes()
    return (
        b"\3" + head + _COUNT.pack(len(flat)) + flat.astype("<u4").tobytes() + marks.cells.reshape(-1)[flat].tobytes()
    )


def _decode_marks(base: MarksGrid | None, data: bytes, at: int) -> tuple[MarksGrid | None, int]:
    """The tracks after a frame's tracks part at ``at``, and where the part ends."""

    def need(n: int) -> None:
        if at + n > len(data):
            raise FrameError("frame ends inside its tracks")

    need(1)
    mode = data[at]
    at += 1
    if mode == 0:
        return None, at
    if mode == 1:
        if base is None:
            raise FrameError("unchanged tracks, but the page has none")
        return base, at
    if mode not in (2, 3):
        raise FrameError(f"unknown tracks mode {mode}")
    need(_GRID.size)
    nx, nz, x0, z0, cell = _GRID.unpack_from(data, at)
    at += _GRID.size
    if nx * nz > MAX_MARKS_CELLS:
        raise FrameError(f"tracks grid of {nx} × {nz} cells (at most {MAX_MARKS_CELLS})")
    if not (np.isfinite([x0, z0]).all() and 0.0 < cell < 1e3):
        raise FrameError(f"tracks grid at ({x0}, {z0}) with cells of {cell} m")
    cells = np.zeros((nz, nx), dtype=np.uint8)
    if base is not None and base.cells.shape == (nz, nx) and (base.x0, base.z0, base.cell) == (x0, z0, cell):
        cells[:] = base.cells
    if mode == 2:
        need(_RECT.size)
        r0, c0, h, w = _RECT.unpack_from(data, at)
        at += _RECT.size
        if r0 + h > nz or c0 + w > nx:
            raise FrameError("tracks rectangle outside the grid")
        need(h * w)
        cells[r0 : r0 + h, c0 : c0 + w] = np.frombuffer(data, np.uint8, h * w, at).reshape(h, w)
        at += h * w
    else:
        need(_COUNT.size)
        (count,) = _COUNT.unpack_from(data, at)
        at += _COUNT.size
        need(5 * count)
        index = np.frombuffer(data, "<u4", count, at)
        if count and int(index.max()) >= nx * nz:
            raise FrameError("tracks cell outside the grid")
        cells.reshape(-1)[index] = np.frombuffer(data, np.uint8, count, at + 4 * count)
        at += 5 * count
    return MarksGrid(cells, x0, z0, cell), at


def encode_frame(base: SceneState, state: SceneState) -> bytes:
    """The bytes that take a phone holding ``base`` to ``state``."""
    cam = state.camera
    out = [
        _HEADER.pack(
            b"PF", FRAME_VERSION, 0, state.step & 0xFFFFFFFF, state.published, *cam.position, *cam.rotation, cam.fov_y
        )
    ]
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
    out.append(_encode_marks(base.marks, state.marks))
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
            if mode not in (1, 2):
                raise FrameError(f"unknown mode {mode} for the {kind}")
            (bits,) = _COLUMNS.unpack_from(data, at)
            if bits == 0 or bits >> len(scales):
                raise FrameError(f"changed-column bits {bits:#06x} for {len(scales)} columns of {kind}")
            columns = np.array([(bits >> c) & 1 for c in range(len(scales))], dtype=bool)
            at += _COLUMNS.size
            changed = np.unpackbits(np.frombuffer(data, np.uint8, mask_len, at), count=n, bitorder="little").astype(
                bool
            )
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
    marks, at = _decode_marks(base.marks, data, at)
    if at != len(data):
        raise FrameError("bytes after the tracks")
    pose = CameraPose(tuple(cam[0:3]), tuple(cam[3:7]), cam[7])
    return SceneState(step, published, pose, rows, marks)
