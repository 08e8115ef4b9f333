"""Recordings: a header, then per step the ``InputFrame`` and the ``state_hash``.

File layout (little-endian)::

    b"PPREC\\n"  u32 header_len  u32 crc32(header)  header (UTF-8 JSON)
    record*  =  u32 payload_len  u32 crc32(payload)  payload
    payload  =  16-byte state hash  +  parts  +  input/codec.py frame
    parts    =  u8 flags  [u16 n  names (UTF-8, newline-separated) if flags & 1]
                u8 count  count × 2-byte part digest

A finished recording ends with a closing record (format 4): ``u32 0  u32 frame_count`` (a
length no real record has). A file without it was cut — the session was killed (``kill -9``)
or the disk filled — even when the cut fell exactly between two records, and the reader
says so ("ended without its closing record") instead of replaying it as complete.

``parts`` (format 3) holds a short digest of each named part of the state — a component
type, a resource, the RNG (:func:`engine.hashing.state_parts`) — so a replay that
diverges names what differs first; the part names are written only when they change
from the record before (a type appears or goes). Two bytes name a differing part well
enough (the 16-byte hash decides whether a step matches).

The header holds ``format`` (this module's :data:`FORMAT_VERSION`), ``engine_version``,
``libraries`` (the versions of the libraries that change numbers, :mod:`input.library_versions`;
absent in recordings made before, which read as ``{}``), ``game``, ``seed``, ``dt``, ``sources`` and ``setup`` — the game's explicit set-up (options,
a save's contents: see :mod:`games.base`), so a replay needs nothing but the file.

Why a recording is append-only rather than written to a temporary file and renamed like every
other save (:mod:`engine.atomic`): it grows for the whole session, and a file that grows cannot
be renamed into place atomically at every step (that would rewrite the whole recording 60
times a second). Appending loses nothing instead: every record is flushed to the OS after its
step and the file is fsynced every :data:`FSYNC_EVERY` records, so a crash, a ``kill -9`` or a
power cut at any byte loses at most the last second; :func:`read_recording` returns every
complete, checksummed record before the cut and says why it stopped (the replay prints that as
a warning, "ended without its closing record"), never a silently shorter "complete" file.

A write that fails (a full disk, the folder made read-only) does not stop the recording: what is
already on disk is copied to the user's recovery folder (:mod:`engine.recovery`) and the
recording goes on there, with one line on the terminal naming the new file, which ends with
its closing record like any finished recording. Only when that fails too does the recording
stop (one line); the session itself plays on either way.

Size per minute of play (60 steps/s; measured by ``tests/input/test_recording.py``
and the figures in the closing report):

- the part digests: 2 bytes per state part (26 in a snowman game): ≈ 54 bytes per frame,
  **≈ 190 KB/min**, on top of what follows;
- input, idle frames (no input): 31 bytes each, **≈ 112 KB/min**;
- mouse dragging (one world-mode sample with pivot and plane normal every step):
  about 127 bytes per frame, **≈ 460 KB/min** (less when the mouse is still);
- a 60 Hz phone (orientation + gyro + accel, one sample per step, a
  ``osc:192.168.1.23`` source id): about 138 bytes per frame, **≈ 500 KB/min**;
  a 6-DoF phone adds 24 bytes per frame (**≈ 590 KB/min**).
"""

from __future__ import annotations

import io
import json
import os
import struct
import sys
import zlib
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path
from typing import Any, BinaryIO

from engine.app import App
from engine.ecs import World
from engine.errors import FormatError
from engine.hashing import PART_DIGEST_SIZE, part_digests
from engine.npz_safe import read_bounded
from input.codec import CodecError, decode_frame, encode_frame
from input.library_versions import libraries_problem, running_versions
from input.sample import InputFrame

__all__ = [
    "FORMAT_VERSION",
    "MAGIC",
    "RecordingHeader",
    "Recording",
    "Recorder",
    "RecordingError",
    "read_recording",
    "MAX_RECORDING",
]

FORMAT_VERSION = 4
#: The first format whose records carry per-part digests.
PARTS_FORMAT = 3
#: The first format whose finished files end with a closing record.
CLOSING_FORMAT = 4
MAGIC = b"PPREC\n"
# An hour of a 60 Hz phone is about 30 MB; a header holds a game's saved field (a few KB).
MAX_RECORDING = 512 << 20
MAX_HEADER = 16 << 20
MIN_DT, MAX_DT = 1e-4, 1.0
#: Records between two fsyncs of a growing recording (one second at 60 steps/s).
FSYNC_EVERY = 60
_LEN = struct.Struct("<II")


class RecordingError(FormatError):
    """The file is not a recording, or its header is damaged (nothing can be replayed)."""


def _engine_version() -> str:
    try:
        from importlib.metadata import version

        return version("puppetphone")
    except Exception:  # not installed (a bare checkout): say so rather than fail the recording
        return "unknown"


@dataclass
class RecordingHeader:
    """What a replay needs to rebuild the same app."""

    game: str
    seed: int
    dt: float
    sources: list[str] = field(default_factory=list)
    setup: dict[str, Any] = field(default_factory=dict)
    format: int = FORMAT_VERSION
    engine_version: str = field(default_factory=_engine_version)
    extra: dict[str, Any] = field(default_factory=dict)
    libraries: dict[str, str] = field(default_factory=running_versions)


@dataclass
class Recording:
    """A read recording: every complete frame, its hash, and whether the file was cut.

    ``parts[i]`` maps each part name of step ``i`` to its short digest (empty for
    recordings older than format 3).
    """

    header: RecordingHeader
    frames: list[InputFrame]
    hashes: list[str]
    complete: bool = True
    problem: str = ""
    parts: list[dict[str, bytes]] = field(default_factory=list)
    cut: bool = False  # the file stops short (killed mid-session), as opposed to damaged

    def __len__(self) -> int:
        return len(self.frames)


class Recorder:
    """Appends one record per step to an open file and flushes it.

    Args:
        path: the file to create (an existing file is replaced).
        header: game, seed, dt and sources of the session.
    """

    def __init__(self, path: str | Path, header: RecordingHeader) -> None:
        self.path = Path(path)
        self.header = header
        head = json.dumps(asdict(header), sort_keys=True).encode()
        self._file: BinaryIO | None = open(self.path, "wb")  # noqa: SIM115 - kept open while recording
        self._file.write(MAGIC + _LEN.pack(len(head), zlib.crc32(head)) + head)
        self._file.flush()
        self.frames = 0
        self.bytes = self._file.tell()
        self._names: tuple[str, ...] = ()
        self.failed = ""  # why the recording stopped early ("" while it is fine)

    def attach(self, app: App) -> Recorder:
        """Write a record at the end of every step of ``app`` (``app.on_step_end``)."""
        app.on_step_end.append(self.on_step_end)
        return self

    def on_step_end(self, world: World) -> None:
        """Record the step that just ran: its ``InputFrame``, the state hash and its parts."""
        digest, parts = part_digests(world)
        self.write(world.resource(InputFrame), digest, parts)

    def write(self, frame: InputFrame, digest: str, parts: dict[str, bytes] | None = None) -> None:
        """Append one record and flush it to the OS (after a failed write: nothing, see :attr:`failed`)."""
        if self._file is None:
            if self.failed:
                return
            raise RecordingError(f"recording {self.path} is closed")
        payload = bytes.fromhex(digest) + self._parts_block(parts or {}) + encode_frame(frame)
        if self._put(_LEN.pack(len(payload), zlib.crc32(payload)) + payload):
            self.frames += 1
            self.bytes += _LEN.size + len(payload)

    def _put(self, data: bytes) -> bool:
        """Write and flush (fsync every :data:`FSYNC_EVERY` records); a failure moves the recording to the
        recovery folder, or stops it with one line, never the session."""
        assert self._file is not None
        try:
            self._file.write(data)
            self._file.flush()
            if (self.frames + 1) % FSYNC_EVERY == 0:
                os.fsync(self._file.fileno())
        except OSError as exc:
            why = exc.strerror or str(exc)
            try:
                self._file.close()
            except OSError:
                pass  # what did not fit is written again below, after the part that did
            self._file = None
            return self._go_on_elsewhere(data, why)
        return True

    def _go_on_elsewhere(self, data: bytes, why: str) -> bool:
        """Copy what is on disk so far to the recovery folder and go on there; ``False`` when that fails too."""
        from engine.recovery import free_recovery_path

        target = free_recovery_path(self.path.name, avoid=self.path)
        try:
            with open(self.path, "rb") as f:
                written = f.read(self.bytes)  # every record before this one was flushed whole
            if len(written) != self.bytes:
                raise OSError(f"only {len(written)} of its {self.bytes} bytes can be read back")
            target.parent.mkdir(parents=True, exist_ok=True)
            moved = open(target, "wb")  # noqa: SIM115 - kept open while recording
            try:
                moved.write(written + data)
                moved.flush()
                os.fsync(moved.fileno())
            except OSError:
                moved.close()
                raise
        except OSError as exc:
            self.failed = (
                f"recording {self.path} stopped after {self.frames} frames: {why} "
                f"(and not in {target.parent} either: {exc.strerror or exc})"
            )
            print(self.failed, file=sys.stderr)
            return False
        print(
            f"recording {self.path}: {why} after {self.frames} frames; it goes on in {target} (replay that file)",
            file=sys.stderr,
        )
        self.path, self._file = target, moved
        return True

    def _parts_block(self, parts: dict[str, bytes]) -> bytes:
        names = tuple(parts)
        if len(names) > 255:
            raise RecordingError(f"{len(names)} state parts; a record holds at most 255")
        block = bytearray()
        if names != self._names:
            listed = "\n".join(names).encode()
            block += b"\x01" + struct.pack("<H", len(listed)) + listed
            self._names = names
        else:
            block += b"\x00"
        block += bytes([len(names)]) + b"".join(parts.values())
        return bytes(block)

    def close(self) -> None:
        """Write the closing record, sync and close (idempotent)."""
        if self._file is None or not self._put(_LEN.pack(0, self.frames)):
            return
        f, self._file = self._file, None
        try:
            os.fsync(f.fileno())
            f.close()
        except OSError as exc:
            self.failed = f"recording {self.path} may be incomplete: {exc.strerror or exc}"
            print(self.failed, file=sys.stderr)
            f.close()

    def __enter__(self) -> Recorder:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _read_header(f: io.BufferedIOBase | BinaryIO, name: str) -> RecordingHeader:
    magic = f.read(len(MAGIC))
    if magic != MAGIC:
        raise RecordingError(f"{name} is not a PuppetPhone recording (bad magic)")
    raw = f.read(_LEN.size)
    if len(raw) < _LEN.size:
        raise RecordingError(f"{name} is cut inside its header")
    n, crc = _LEN.unpack(raw)
    if n > MAX_HEADER:
        raise RecordingError(f"{name} claims a {n}-byte header; the limit is {MAX_HEADER}")
    head = f.read(n)
    if len(head) < n:
        raise RecordingError(f"{name} is cut inside its header")
    if zlib.crc32(head) != crc:
        raise RecordingError(f"{name} has a damaged header (checksum mismatch)")
    try:
        d = json.loads(head)
    except (ValueError, RecursionError) as exc:
        raise RecordingError(f"{name} has an unreadable header: {type(exc).__name__}") from None
    problem = _header_problem(d)
    if problem:
        raise RecordingError(f"{name} has a bad header: {problem}")
    header = RecordingHeader(**{"libraries": {}, **d})  # an older file recorded no versions: none, not ours
    if header.format > FORMAT_VERSION:
        raise RecordingError(f"{name} is format {header.format}; this build reads up to {FORMAT_VERSION}")
    return header


def _is_int(v: object) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)


def _header_problem(d: object) -> str:
    """What is wrong with a decoded header (``""`` if nothing): every field's type and range."""
    if not isinstance(d, dict):
        return "not a JSON object"
    known = {f.name for f in fields(RecordingHeader)}
    unknown = sorted(set(d) - known)
    if unknown:
        return f"unknown fields {', '.join(map(repr, unknown))[:100]}"
    missing = sorted({"game", "seed", "dt"} - set(d))
    if missing:
        return f"missing {', '.join(missing)}"
    game, seed, dt = d["game"], d["seed"], d["dt"]
    if not isinstance(game, str) or not 0 < len(game) <= 64:
        return "game must be a name of 1..64 characters"
    if not _is_int(seed) or not 0 <= seed < 2**63:
        return "seed must be a whole number in 0..2**63-1"
    if isinstance(dt, bool) or not isinstance(dt, (int, float)) or not MIN_DT <= dt <= MAX_DT:
        return f"dt must be a number of seconds in [{MIN_DT}, {MAX_DT}]"
    if "format" in d and (not _is_int(d["format"]) or d["format"] < 1):
        return "format must be a whole number from 1"
    if not isinstance(d.get("sources", []), list) or not all(isinstance(x, str) for x in d.get("sources", [])):
        return "sources must be a list of names"
    if not isinstance(d.get("engine_version", ""), str) or not isinstance(d.get("extra", {}), dict):
        return "engine_version must be a string and extra an object"
    if "libraries" in d and (problem := libraries_problem(d["libraries"])):
        return problem
    if not isinstance(d.get("setup", {}), dict):
        return "setup must be an object (the game checks its values when it rebuilds the session)"
    return ""


def read_recording(path: str | Path) -> Recording:
    """Read every complete frame; a cut or damaged tail ends the list with ``complete=False``.

    Raises:
        RecordingError: not a regular file (``/dev/zero``, a pipe), over :data:`MAX_RECORDING`
            bytes, not a recording, or a header that is damaged or has wrong types or ranges.
        OSError: the file cannot be opened.
    """
    path = Path(path)
    try:
        data = read_bounded(path, MAX_RECORDING)
    except ValueError as exc:  # a device, a pipe, a folder, or too big: never read without end
        raise RecordingError(str(exc)) from None
    f = io.BytesIO(data)
    header = _read_header(f, str(path))
    frames: list[InputFrame] = []
    hashes: list[str] = []
    parts: list[dict[str, bytes]] = []
    names: tuple[str, ...] = ()
    pos = f.tell()
    problem, closed = "", header.format < CLOSING_FORMAT
    while pos < len(data):
        if pos + _LEN.size > len(data):
            problem = f"cut inside the record of frame {len(frames)} (byte {pos})"
            break
        n, crc = _LEN.unpack_from(data, pos)
        if n == 0 and header.format >= CLOSING_FORMAT:
            if crc != len(frames) or pos + _LEN.size != len(data):
                problem = f"damaged closing record after frame {len(frames)} (byte {pos})"
            closed = not problem
            break
        payload = data[pos + _LEN.size : pos + _LEN.size + n]
        if len(payload) < n:
            problem = f"cut inside the record of frame {len(frames)} (byte {pos})"
            break
        if zlib.crc32(payload) != crc or n < 16:
            problem = f"damaged record at frame {len(frames)} (byte {pos}, checksum mismatch)"
            break
        try:
            start = 16
            if header.format >= PARTS_FORMAT:
                names, digests, start = _read_parts(payload, names)
                parts.append(digests)
            frame = decode_frame(payload[start:])
        except CodecError as exc:
            problem = f"undecodable record at frame {len(frames)}: {exc}"
            break
        frames.append(frame)
        hashes.append(payload[:16].hex())
        pos += _LEN.size + n
    cut = problem.startswith("cut inside")
    if not problem and not closed:
        problem, cut = f"cut: ended without its closing record after {len(frames)} frames (killed mid-session?)", True
    return Recording(
        header=header,
        frames=frames,
        hashes=hashes,
        complete=not problem,
        problem=problem,
        parts=parts[: len(frames)],
        cut=cut,
    )


def _read_parts(payload: bytes, names: tuple[str, ...]) -> tuple[tuple[str, ...], dict[str, bytes], int]:
    """The parts block at byte 16: (current names, digests by name, where the frame starts)."""
    pos = 16
    if len(payload) < pos + 2:
        raise CodecError("record too short for its parts")
    if payload[pos] & 1:
        (n,) = struct.unpack_from("<H", payload, pos + 1)
        listed = payload[pos + 3 : pos + 3 + n]
        if len(listed) < n:
            raise CodecError("part names cut short")
        try:
            names = tuple(listed.decode().split("\n")) if n else ()
        except UnicodeDecodeError:
            raise CodecError("part names are not UTF-8") from None
        pos += 3 + n
    else:
        pos += 1
    if pos >= len(payload):
        raise CodecError("record too short for its parts")
    count = payload[pos]
    pos += 1
    end = pos + count * PART_DIGEST_SIZE
    if count != len(names) or end > len(payload):
        raise CodecError(f"{count} part digests for {len(names)} part names")
    digests = {
        name: payload[pos + i * PART_DIGEST_SIZE : pos + (i + 1) * PART_DIGEST_SIZE] for i, name in enumerate(names)
    }
    return names, digests, end
