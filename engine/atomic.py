"""Atomic, verified file writes: the one way the product saves anything a person made.

Every save (fields, quest progress, clips and their side files, libraries, exports)
writes a temporary file beside the target, fsyncs it, reads it back and compares its
SHA-256 with the bytes meant to be written, and only then renames it over the target
and fsyncs the folder. A crash, a full disk or a bad write therefore leaves the old
file intact, never a half-written or silently different one, and the rename is
durable once the call returns.

A failure is a :class:`WriteError` (an ``OSError``) whose message is one line naming
the file and the reason, so a game can print it, keep running and keep the unsaved
work in memory. ``expect_head`` guards the other direction: a target that exists and
does not begin with one of the product's own headers (a user's folder, a device, a
text file named by ``--set save=PATH``) is never replaced; :func:`set_aside` likewise
renames a damaged save to ``*.bad`` only when it is a regular file that the product wrote.

The new file gets the mode a plain ``open`` would give it (the old file's mode, or 0666
less the umask), not the private 0600 of a temporary file. A write that was killed
(``kill -9``, power cut) leaves its temporary behind; the next write to the same file
removes such leftovers once they are :data:`STALE_AFTER` seconds old (younger ones may
belong to a write still in progress).
"""

from __future__ import annotations

import hashlib
import io
import os
import stat
import tempfile
import threading
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import BinaryIO

__all__ = ["atomic_write", "atomic_write_bytes", "set_aside", "is_own_file", "WriteError", "STALE_AFTER"]

STALE_AFTER = 30.0
_HEAD_BYTES = 256  # how much of a file is read to recognise the product's own header


class WriteError(OSError):
    """A save that did not happen (the previous file, if any, is intact); ``str`` is one line."""

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else "write failed"


def _remove_stale_temporaries(target: Path) -> None:
    cutoff = time.time() - STALE_AFTER
    for tmp in target.parent.glob(f".{target.name}.*.tmp"):
        try:
            if tmp.stat().st_mtime < cutoff:
                tmp.unlink()
        except OSError:
            pass  # gone already, or not ours to remove: the write itself is what matters


_UMASK_LOCK = threading.Lock()


def _file_mode(target: Path) -> int:
    """The mode ``target`` would have if written in place."""
    try:
        return target.stat().st_mode & 0o7777
    except FileNotFoundError:
        with _UMASK_LOCK:  # os.umask can only be read by setting it
            umask = os.umask(0o022)
            os.umask(umask)
        return 0o666 & ~umask


def is_own_file(path: str | os.PathLike[str], heads: Sequence[bytes]) -> bool:
    """Whether ``path`` is a regular file (not a link, folder, device or pipe) beginning with one of ``heads``."""
    try:
        st = os.lstat(path)
        if not stat.S_ISREG(st.st_mode):
            return False
        with open(path, "rb") as f:
            head = f.read(_HEAD_BYTES)
    except OSError:
        return False
    return any(head.startswith(h) for h in heads)


def _why_not_replace(target: Path, heads: Sequence[bytes]) -> str:
    """Why ``target`` must not be replaced by a save expecting ``heads`` ("" when it may)."""
    try:
        st = os.lstat(target)
    except FileNotFoundError:
        return ""
    except OSError as exc:
        return exc.strerror or str(exc)
    if stat.S_ISDIR(st.st_mode):
        return "it is a folder"
    if not stat.S_ISREG(st.st_mode):
        return "it is not a regular file (a device, pipe or link)"
    if not is_own_file(target, heads):
        return "it is not a file this program wrote; it is left as it is"
    return ""


def _fsync_folder(folder: Path) -> None:
    """Make the rename durable (best effort: some file systems cannot sync a folder)."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def _write_verified(target: Path, data: bytes) -> None:
    target.parent.mkdir(parents=True, exist_ok=True)
    _remove_stale_temporaries(target)
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        with open(tmp, "rb") as f:
            back = hashlib.sha256(f.read()).digest()
        if back != hashlib.sha256(data).digest():
            raise WriteError(f"cannot save {target}: what was read back differs from what was written")
        os.chmod(tmp, _file_mode(target))
        os.replace(tmp, target)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    _fsync_folder(target.parent)


def atomic_write_bytes(
    path: str | os.PathLike[str], data: bytes, *, expect_head: Sequence[bytes] | None = None
) -> Path:
    """Atomically replace ``path`` with ``data``, verified by reading it back.

    Args:
        expect_head: when given, an existing ``path`` is replaced only if it is a regular
            file beginning with one of these headers (a save of this product).

    Raises:
        WriteError: nothing was written (full disk, no permission, a folder in the way,
            a foreign file at ``path``, a read-back that differs); the old file is intact.
    """
    target = Path(path)
    if expect_head is not None and (why := _why_not_replace(target, expect_head)):
        raise WriteError(f"cannot save {target}: {why}")
    try:
        _write_verified(target, data)
    except WriteError:
        raise
    except OSError as exc:
        raise WriteError(f"cannot save {target}: {exc.strerror or exc}") from None
    return target


def atomic_write(path: str | os.PathLike[str], write: Callable[[BinaryIO], object]) -> Path:
    """Call ``write(f)`` on an in-memory file, then :func:`atomic_write_bytes` its bytes to ``path``."""
    buf = io.BytesIO()
    write(buf)
    return atomic_write_bytes(path, buf.getvalue())


def set_aside(path: str | os.PathLike[str], heads: Sequence[bytes]) -> Path | None:
    """Rename a damaged save to a free ``<path>.bad`` name; ``None`` (nothing moved) unless it is the product's.

    Only a regular file beginning with one of ``heads`` is moved: a folder, device, pipe,
    link or anyone else's file stays exactly where it is, and no existing ``.bad`` is replaced.

    Raises:
        WriteError: the file is the product's but cannot be moved (no permission, no free name).
    """
    source = Path(path)
    if not is_own_file(source, heads):
        return None
    for n in range(100):
        bad = Path(f"{source}.bad" if n == 0 else f"{source}.{n}.bad")
        if os.path.lexists(bad):
            continue
        try:
            os.rename(source, bad)
        except OSError as exc:
            raise WriteError(f"cannot set {source} aside: {exc.strerror or exc}") from None
        return bad
    raise WriteError(f"cannot set {source} aside: {source}.bad and 99 more names are taken")
