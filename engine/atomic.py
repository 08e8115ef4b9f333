"""Atomic file writes: write a temporary file beside the target, fsync, then rename.

A crash or a full disk mid-write leaves the old file intact, never a half-written
one: authored cycles, saved fields and quest progress must not be lost. The new file
gets the mode a plain ``open`` would give it (the old file's mode, or 0666 less the
umask), not the private 0600 of a temporary file. A write that
was killed (``kill -9``, power cut) leaves its temporary behind; the next write to
the same file removes such leftovers once they are :data:`STALE_AFTER` seconds old
(younger ones may belong to a write still in progress).
"""

from __future__ import annotations

import os
import tempfile
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import BinaryIO

__all__ = ["atomic_write", "atomic_write_bytes", "STALE_AFTER"]

STALE_AFTER = 30.0


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


def atomic_write(path: str | os.PathLike[str], write: Callable[[BinaryIO], None]) -> Path:
    """Call ``write(f)`` on a temporary file, then rename it over ``path``."""
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    _remove_stale_temporaries(target)
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
    try:
        with os.fdopen(fd, "wb") as f:
            write(f)
            f.flush()
            os.fsync(f.fileno())
        os.chmod(tmp, _file_mode(target))
        os.replace(tmp, target)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return target


def atomic_write_bytes(path: str | os.PathLike[str], data: bytes) -> Path:
    """Atomically replace ``path`` with ``data``."""
    return atomic_write(path, lambda f: f.write(data))
