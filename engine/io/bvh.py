"""BVH motion files: read and write the raw hierarchy and channel matrix, losslessly.

A :class:`BvhMotion` keeps the file as the file says it: joint names, parents, OFFSETs,
End Sites, each joint's CHANNELS list in file order, the frame time and the raw channel
matrix ``[F, C]``. Nothing is converted on read, so ``read → write → read`` gives the
same numbers, and tools that want the raw Euler curves (cycle extraction) can have them.
Turning the raw channels into a skeleton and quaternion clip — with the quirks real files
have (position channels that replace OFFSETs, per-joint rotation orders, unit detection)
— is :meth:`BvhMotion.to_clip`, implemented in :mod:`engine.io.bvh_convert`.

Parsing is line-based for the small hierarchy (so every error names file and line) and
one vectorised numpy conversion for the motion block.
"""

from __future__ import annotations

import io
import os
import warnings
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from engine.atomic import atomic_write_bytes
from engine.errors import FormatError
from engine.npz_safe import read_bounded

if TYPE_CHECKING:
    from engine.clip import Clip

__all__ = ["BvhError", "BvhWarning", "BvhMotion", "read_bvh", "write_bvh", "parse_bvh", "format_bvh", "CHANNEL_NAMES"]

CHANNEL_NAMES = ("Xposition", "Yposition", "Zposition", "Xrotation", "Yrotation", "Zrotation")
# Limits a real capture is far inside (CMU: 31 joints, 120 fps, centimetres and degrees).
MAX_FILE = 512 << 20
MAX_JOINTS = 1024
MAX_VALUE = 1e7
MAX_FRAME_TIME = 10.0
_CANON = {c.lower(): c for c in CHANNEL_NAMES}


class BvhError(FormatError):
    """A BVH file that cannot be read; the message names the file and line."""


class BvhWarning(UserWarning):
    """A BVH file read despite a harmless inconsistency (a ``Frames:`` count that is off)."""


@dataclass(frozen=True)
class BvhMotion:
    """The content of a BVH file, unconverted.

    Attributes:
        names: joint names in file order (ROOT first; End Sites are not joints).
        parents: ``[J]`` parent index per joint, ``-1`` for the root.
        offsets: ``[J,3]`` OFFSET of each joint, in file units.
        end_sites: joint index → ``[3]`` OFFSET of that joint's End Site.
        channels: per joint, its CHANNELS names in file order (canonical capitalisation).
        frame_time: seconds per frame.
        data: ``[F, C]`` channel values exactly as in the file, joints in file order.
        source: where it was read from (for messages), or ``""``.
    """

    names: tuple[str, ...]
    parents: NDArray[np.int64]
    offsets: NDArray[np.float64]
    end_sites: dict[int, NDArray[np.float64]]
    channels: tuple[tuple[str, ...], ...]
    frame_time: float
    data: NDArray[np.float64]
    source: str = field(default="", compare=False)

    def __post_init__(self) -> None:
        n = len(self.names)
        if np.shape(self.parents) != (n,) or np.shape(self.offsets) != (n, 3) or len(self.channels) != n:
            raise BvhError(f"{self.source or 'BVH'}: names, parents, offsets and channels disagree in length")
        width = sum(len(c) for c in self.channels)
        data = np.asarray(self.data, dtype=np.float64)
        if data.ndim != 2 or data.shape[1] != width:
            raise BvhError(f"{self.source or 'BVH'}: data must be [F,{width}], got {data.shape}")
        if not self.frame_time > 0:
            raise BvhError(f"{self.source or 'BVH'}: frame time must be positive, got {self.frame_time}")
        object.__setattr__(self, "data", data)

    @property
    def num_frames(self) -> int:
        """Number of frames ``F``."""
        return int(self.data.shape[0])

    @property
    def num_joints(self) -> int:
        """Number of joints ``J`` (End Sites excluded)."""
        return len(self.names)

    @property
    def fps(self) -> float:
        """Frames per second, ``1 / frame_time``."""
        return 1.0 / self.frame_time

    def channel_offsets(self) -> NDArray[np.int64]:
        """``[J+1]`` start column of each joint's channels in :attr:`data` (last entry = ``C``)."""
        return np.concatenate([[0], np.cumsum([len(c) for c in self.channels])]).astype(np.int64)

    def column(self, joint: str | int, channel: str) -> NDArray[np.float64]:
        """The ``[F]`` values of one channel of one joint, e.g. ``column("hip", "Yposition")``."""
        j = joint if isinstance(joint, int) else self.names.index(joint)
        k = self.channels[j].index(_CANON[channel.lower()])
        return self.data[:, self.channel_offsets()[j] + k]

    def rotation_columns(self) -> NDArray[np.bool_]:
        """``[C]`` mask of the rotation channels."""
        return np.array([c.endswith("rotation") for chans in self.channels for c in chans], dtype=bool)

    def unwrapped(self) -> BvhMotion:
        """A copy whose rotation channels are unwrapped in time (no ±360° single-frame jumps).

        The Bandai clips flip between +180° and -180°; curve fitting and cycle detection on
        raw Euler channels need continuous curves. The rotations themselves are unchanged.
        """
        data = self.data.copy()
        rot = self.rotation_columns()
        if len(data):
            data[:, rot] = np.unwrap(data[:, rot], period=360.0, axis=0)
        return replace(self, data=data)

    def with_frames(self, frames: slice | NDArray[np.int64]) -> BvhMotion:
        """A copy holding only the given frames (e.g. ``slice(5, None)`` to drop a T-pose lead-in)."""
        return replace(self, data=self.data[frames])

    def to_clip(
        self, scale: float | None = None, skip_frames: int = 0, name: str | None = None, positions: str = "auto"
    ) -> Clip:
        """Convert to a :class:`~engine.clip.Clip` in metres; see :func:`engine.io.bvh_convert.bvh_to_clip`."""
        from engine.io.bvh_convert import bvh_to_clip

        return bvh_to_clip(self, scale=scale, skip_frames=skip_frames, name=name, positions=positions)


def _floats(tokens: list[str], where: str) -> NDArray[np.float64]:
    try:
        return np.array([float(t) for t in tokens], dtype=np.float64)
    except ValueError:
        raise BvhError(f"{where}: expected numbers, got {' '.join(tokens)!r}") from None


def parse_bvh(text: str, source: str = "<string>") -> BvhMotion:
    """Parse BVH text; :class:`BvhError` names ``source`` and the line of any problem."""
    lines = text.splitlines()
    names: list[str] = []
    parents: list[int] = []
    offsets: list[NDArray[np.float64]] = []
    channels: list[tuple[str, ...]] = []
    end_sites: dict[int, NDArray[np.float64]] = {}
    stack: list[int] = []  # joint indices of open braces; -2 marks an End Site block
    pending: int | None = None  # joint (or -2) declared, waiting for its "{"
    i = 0
    n_lines = len(lines)

    def where(k: int) -> str:
        return f"{source}:{k + 1}"

    while i < n_lines and not lines[i].strip():
        i += 1
    if i >= n_lines or lines[i].split()[0].upper() != "HIERARCHY":
        raise BvhError(f"{where(i if i < n_lines else 0)}: not a BVH file (no HIERARCHY header)")
    i += 1
    while i < n_lines:
        tok = lines[i].split()
        if not tok:
            i += 1
            continue
        key = tok[0].upper()
        if key in ("ROOT", "JOINT"):
            if (key == "ROOT") != (not stack) or pending is not None:
                raise BvhError(f"{where(i)}: unexpected {tok[0]} here")
            if len(tok) < 2:
                raise BvhError(f"{where(i)}: {tok[0]} without a name")
            name = " ".join(tok[1:])
            if name in names:
                raise BvhError(f"{where(i)}: duplicate joint name {name!r}")
            if stack and stack[-1] == -2:
                raise BvhError(f"{where(i)}: a joint inside an End Site")
            if len(names) >= MAX_JOINTS:
                raise BvhError(f"{where(i)}: more than {MAX_JOINTS} joints")
            names.append(name)
            parents.append(stack[-1] if stack else -1)
            offsets.append(np.zeros(3))
            channels.append(())
            pending = len(names) - 1
        elif key == "END":
            if not stack or stack[-1] == -2 or pending is not None:
                raise BvhError(f"{where(i)}: End Site outside a joint")
            pending = -2
        elif key == "{":
            if pending is None:
                raise BvhError(f"{where(i)}: '{{' without a ROOT, JOINT or End Site before it")
            stack.append(pending)
            pending = None
        elif key == "}":
            if not stack:
                raise BvhError(f"{where(i)}: unbalanced '}}'")
            stack.pop()
        elif key == "OFFSET":
            if not stack or len(tok) != 4:
                raise BvhError(f"{where(i)}: OFFSET needs 3 numbers inside a joint")
            value = _floats(tok[1:], where(i))
            if not np.isfinite(value).all() or np.abs(value).max() > MAX_VALUE:
                raise BvhError(f"{where(i)}: OFFSET must be finite and within ±{MAX_VALUE:g}")
            if stack[-1] == -2:
                end_sites.setdefault(stack[-2], value)
            else:
                offsets[stack[-1]] = value
        elif key == "CHANNELS":
            if not stack or stack[-1] == -2:
                raise BvhError(f"{where(i)}: CHANNELS outside a joint")
            try:
                count = int(tok[1])
            except (IndexError, ValueError):
                raise BvhError(f"{where(i)}: CHANNELS needs a count") from None
            chans = tok[2:]
            if count != len(chans):
                raise BvhError(f"{where(i)}: CHANNELS says {count} but lists {len(chans)}")
            bad = [c for c in chans if c.lower() not in _CANON]
            if bad or len({c.lower() for c in chans}) != len(chans):
                raise BvhError(f"{where(i)}: bad channel list {' '.join(chans)!r}")
            channels[stack[-1]] = tuple(_CANON[c.lower()] for c in chans)
        elif key == "MOTION":
            break
        else:
            raise BvhError(f"{where(i)}: unexpected {tok[0]!r} in the hierarchy")
        i += 1
    if not names:
        raise BvhError(f"{where(min(i, n_lines - 1))}: no ROOT joint")
    if stack or pending is not None:
        raise BvhError(f"{where(min(i, n_lines - 1))}: hierarchy ends with unclosed braces")
    if i >= n_lines:
        raise BvhError(f"{source}: no MOTION section")
    motion_line = i
    header: dict[str, str] = {}
    i += 1
    while i < n_lines and len(header) < 2:
        s = lines[i].strip()
        if s:
            key, sep, text = s.partition(":")
            key = " ".join(key.split()).lower()
            if not sep or key not in ("frames", "frame time"):
                raise BvhError(f"{where(i)}: expected 'Frames:' and 'Frame Time:' after MOTION")
            header[key] = text.strip()
        i += 1
    if len(header) < 2:
        raise BvhError(f"{where(motion_line)}: MOTION without 'Frames:' and 'Frame Time:'")
    try:
        n_frames = int(header["frames"])
        frame_time = float(header["frame time"])
    except ValueError:
        raise BvhError(f"{where(i - 1)}: bad frame count or frame time") from None
    if n_frames < 0 or not 0 < frame_time <= MAX_FRAME_TIME:
        raise BvhError(f"{where(i - 1)}: frame count must be >= 0 and frame time in (0, {MAX_FRAME_TIME:g}] s")
    width = sum(len(c) for c in channels)
    data = _motion_block(lines, i, n_frames, width, source)
    if not np.isfinite(data).all() or (data.size and np.abs(data).max() > MAX_VALUE):
        bad = np.argwhere(~(np.abs(data) <= MAX_VALUE))[0]
        raise BvhError(f"{source}: frame {bad[0]} holds a NaN, infinite or absurd value (beyond ±{MAX_VALUE:g})")
    return BvhMotion(
        tuple(names),
        np.array(parents, dtype=np.int64),
        np.array(offsets).reshape(-1, 3),
        end_sites,
        tuple(channels),
        frame_time,
        data,
        source,
    )


def _motion_block(lines: list[str], start: int, n_frames: int, width: int, source: str) -> NDArray[np.float64]:
    """The ``[F, C]`` matrix of the complete rows.

    Tolerant where exporters are sloppy, strict where data is wrong: when the ``Frames:``
    count disagrees with the number of complete rows (off by one in files shipped by a widely
    used importer), the complete rows are read and a :class:`BvhWarning` says so; a row with
    the wrong number of values (a truncated file) or a non-number is refused, naming the line.
    The fast path parses the whole block with numpy's C text reader; only when that fails do
    we walk the lines to say exactly what is wrong.
    """
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # numpy warns (not raises) about some bad input
        try:
            data = np.loadtxt(io.StringIO("\n".join(lines[start:])), dtype=np.float64, ndmin=2, comments=None)
        except (ValueError, UserWarning):
            data = None
    if data is None or (data.size and data.shape[1] != width):
        rows = [(k, ln.split()) for k, ln in enumerate(lines[start:], start) if ln.strip()]
        for f, (k, toks) in enumerate(rows):
            if len(toks) != width:
                raise BvhError(
                    f"{source}:{k + 1}: frame {f} has {len(toks)} values, expected {width}; "
                    f"only {f} of {n_frames} frames are complete (truncated or malformed file)"
                )
            try:
                np.array(toks, dtype=np.float64)
            except ValueError:
                raise BvhError(f"{source}:{k + 1}: frame {f} holds a non-number; {f} frames are complete") from None
        data = np.array([t for _, t in rows], dtype=np.float64).reshape(len(rows), width)
    if data.size == 0:
        data = np.zeros((0, width))
    if len(data) != n_frames:
        warnings.warn(
            BvhWarning(
                f"{source}: 'Frames: {n_frames}' but the file holds {len(data)} complete frames; reading {len(data)}"
            ),
            stacklevel=3,
        )
    return data


def read_bvh(path: str | os.PathLike[str]) -> BvhMotion:
    """Read a BVH file; raises :class:`BvhError` (with file and line) if it is malformed, too big
    (over :data:`MAX_FILE` bytes, :data:`MAX_JOINTS` joints), not a regular file, or holds NaN
    or absurd numbers; ``OSError`` if it cannot be opened."""
    p = Path(path)
    try:
        raw = read_bounded(p, MAX_FILE)
    except ValueError as exc:
        raise BvhError(str(exc)) from None
    try:
        text = raw.decode("utf-8", errors="strict")
    except UnicodeDecodeError:
        text = raw.decode("latin-1")
    return parse_bvh(text, str(p))


def _num(x: float) -> str:
    """Shortest text that reads back as exactly ``x`` (``repr``), without a pointless ``.0``."""
    s = repr(x)
    return s[:-2] if s.endswith(".0") else s


def format_bvh(motion: BvhMotion) -> str:
    """BVH text of ``motion``; numbers are written so that reading gives the same doubles."""
    out = ["HIERARCHY"]
    children: dict[int, list[int]] = {}
    for j, p in enumerate(motion.parents.tolist()):
        children.setdefault(p, []).append(j)

    roots = children.get(-1, [])
    if len(roots) != 1:
        raise BvhError(f"{motion.source or 'BVH'}: need exactly one root joint, found {len(roots)}")
    # Depth first with an explicit stack, not recursion: a hierarchy may be deeper than Python's stack.
    visited: list[int] = []
    todo: list[tuple[int, int, bool]] = [(roots[0], 0, False)]  # joint, depth, closing its brace
    while todo:
        j, depth, closing = todo.pop()
        pad = "  " * depth
        if closing:
            if j in motion.end_sites:
                out.extend(
                    [
                        f"{pad}  End Site",
                        f"{pad}  {{",
                        f"{pad}    OFFSET {' '.join(_num(v) for v in motion.end_sites[j].tolist())}",
                        f"{pad}  }}",
                    ]
                )
            out.append(pad + "}")
            continue
        visited.append(j)
        out.append(f"{pad}{'ROOT' if depth == 0 else 'JOINT'} {motion.names[j]}")
        out.append(pad + "{")
        out.append(f"{pad}  OFFSET {' '.join(_num(v) for v in motion.offsets[j].tolist())}")
        chans = motion.channels[j]
        out.append(f"{pad}  CHANNELS {len(chans)}{' ' if chans else ''}{' '.join(chans)}")
        todo.append((j, depth, True))
        todo.extend((c, depth + 1, False) for c in reversed(children.get(j, [])))
    if visited != list(range(motion.num_joints)):
        raise BvhError(f"{motion.source or 'BVH'}: joints must be in depth-first file order to match the data columns")
    out += ["MOTION", f"Frames: {motion.num_frames}", f"Frame Time: {_num(float(motion.frame_time))}"]
    out += [" ".join(map(_num, row)) for row in motion.data.tolist()]
    return "\n".join(out) + "\n"


def write_bvh(path: str | os.PathLike[str], motion: BvhMotion) -> Path:
    """Write ``motion`` to ``path`` atomically (a crash leaves any old file intact)."""
    if any(p >= j for j, p in enumerate(motion.parents.tolist())):
        raise BvhError(f"{motion.source or 'BVH'}: joints must be in file order (parents first)")
    return atomic_write_bytes(path, format_bvh(motion).encode("utf-8"))
