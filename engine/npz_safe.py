"""Reading ``.npz`` archives from outside without trusting them.

``numpy.load`` on a damaged or hostile archive raises whatever its layers raise
(``BadZipFile``, ``zlib.error``, ``EOFError``, ``ValueError`` …) and allocates what an
array header claims before reading the data: a 200-byte member can ask for 200 GiB.
:func:`read_npz` checks the archive's sizes first (members, their declared sizes, each
array's shape against the bytes it has), refuses object arrays, and turns every failure
into one :class:`NpzError`; the formats built on ``.npz`` (clips, performances) re-raise
it as their own error.
"""

from __future__ import annotations

import io
import math
import os
import stat
import struct
import tokenize
import zipfile
import zlib
from pathlib import Path

import numpy as np
from numpy.lib import format as npy

from engine.errors import FormatError

__all__ = ["NpzError", "read_npz", "read_bounded", "MAX_NPZ_BYTES", "MAX_MEMBERS"]

MAX_NPZ_BYTES = 256 << 20  # uncompressed, all members together
MAX_MEMBERS = 64
# What a corrupt archive can make zipfile and numpy raise.
# (numpy parses an array header with tokenize and ast.literal_eval: TokenError, SyntaxError.)
_ARCHIVE_ERRORS = (
    zipfile.BadZipFile,
    zlib.error,
    OSError,
    EOFError,
    ValueError,
    NotImplementedError,
    RuntimeError,
    struct.error,
    KeyError,
    IndexError,
    OverflowError,
    TypeError,
    SyntaxError,
    tokenize.TokenError,
)


class NpzError(FormatError):
    """An archive that is damaged, too big, or holds something other than plain arrays."""


def read_bounded(path: str | Path, limit: int) -> bytes:
    """The bytes of a regular file of at most ``limit`` bytes (devices, pipes and folders refused).

    Raises:
        OSError: the file cannot be opened (missing, no permission).
        ValueError: not a regular file, or larger than ``limit``.
    """
    # Non-blocking, so that opening a pipe with no writer does not wait forever; fstat then says what it is.
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise ValueError(f"{path} is not a regular file (a device, a pipe or a folder)")
        if st.st_size > limit:
            raise ValueError(f"{path} is {st.st_size} bytes; the limit is {limit}")
        chunks, size = [], 0
        while size <= limit and (chunk := os.read(fd, min(1 << 20, limit + 1 - size))):
            chunks.append(chunk)
            size += len(chunk)
    finally:
        os.close(fd)
    data = b"".join(chunks)
    if len(data) > limit:  # grew while we read it
        raise ValueError(f"{path} is over {limit} bytes")
    return data


def _check_member(zf: zipfile.ZipFile, info: zipfile.ZipInfo) -> None:
    with zf.open(info) as f:
        version = npy.read_magic(f)
        if version == (1, 0):
            shape, _, dtype = npy.read_array_header_1_0(f)
        elif version in ((2, 0), (3, 0)):
            shape, _, dtype = npy.read_array_header_2_0(f)
        else:
            raise NpzError(f"member {info.filename!r}: unsupported .npy version {version}")
    if dtype.hasobject:
        raise NpzError(f"member {info.filename!r} holds Python objects")
    need = math.prod(shape) * dtype.itemsize
    if need > info.file_size:
        raise NpzError(f"member {info.filename!r} claims {need} bytes of data but holds {info.file_size}")


def read_npz(raw: bytes, max_bytes: int = MAX_NPZ_BYTES) -> dict[str, np.ndarray]:
    """Every array of the archive ``raw``, by name; :class:`NpzError` for anything else."""
    try:
        zf = zipfile.ZipFile(io.BytesIO(raw))
        infos = zf.infolist()
        if len(infos) > MAX_MEMBERS:
            raise NpzError(f"{len(infos)} members; the limit is {MAX_MEMBERS}")
        total = sum(i.file_size for i in infos)
        if total > max_bytes:
            raise NpzError(f"{total} bytes uncompressed; the limit is {max_bytes}")
        out: dict[str, np.ndarray] = {}
        for info in infos:
            if not info.filename.endswith(".npy"):
                raise NpzError(f"member {info.filename!r} is not an array")
            _check_member(zf, info)
            with zf.open(info) as f:
                out[info.filename[:-4]] = npy.read_array(f, allow_pickle=False)
        return out
    except NpzError:
        raise
    except _ARCHIVE_ERRORS as exc:
        raise NpzError(f"not a readable .npz archive ({type(exc).__name__}: {exc})"[:300]) from None
