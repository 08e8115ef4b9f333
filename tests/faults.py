"""Real file-system faults for the save tests: a tiny, full disk (a tmpfs) and a read-only folder.

A tmpfs can only be mounted with the right to mount (root, as in CI's container); a
read-only folder stops a writer that is not root by its mode, and root by a read-only
mount. Where a fault cannot be made, the test that needs it is skipped with the reason,
never passed without trying.
"""

from __future__ import annotations

import os
import shutil
import subprocess
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

__all__ = ["full_disk", "read_only_folder"]


@contextmanager
def full_disk(where: Path, free: int = 4096) -> Iterator[Path]:
    """A folder on a 256 KB tmpfs filled up to ``free`` bytes of room (unmounted afterwards)."""
    mount, umount = shutil.which("mount"), shutil.which("umount")
    where.mkdir(parents=True, exist_ok=True)
    if mount is None or umount is None:
        pytest.skip("no mount(8) to make a small disk for the disk-full fault")
    made = subprocess.run(
        [mount, "-t", "tmpfs", "-o", "size=256k", "tmpfs", str(where)], capture_output=True, text=True
    )
    if made.returncode != 0:
        pytest.skip(f"cannot mount a small tmpfs for the disk-full fault: {made.stderr.strip() or 'not permitted'}")
    try:
        filler = where / ".filler"
        fd = os.open(filler, os.O_WRONLY | os.O_CREAT, 0o600)
        try:
            while os.write(fd, b"\0" * 4096):
                pass
        except OSError:
            pass  # full: what we wanted
        finally:
            os.close(fd)
        room = os.statvfs(where).f_bavail * os.statvfs(where).f_frsize
        if room < free:  # give back some room so small writes succeed and large ones fail
            os.truncate(filler, max(0, filler.stat().st_size - (free - room)))
        yield where
    finally:
        subprocess.run([umount, "-l", str(where)], capture_output=True, check=False)


@contextmanager
def read_only_folder(where: Path) -> Iterator[Path]:
    """A folder the writer may not write in: mode 0555, or for root (whom modes do not stop) a
    read-only tmpfs mounted there (skipped when neither can be made)."""
    where.mkdir(parents=True, exist_ok=True)
    if os.geteuid() != 0:
        where.chmod(0o555)
        try:
            yield where
        finally:
            where.chmod(0o755)
        return
    mount, umount = shutil.which("mount"), shutil.which("umount")
    if mount is None or umount is None:
        pytest.skip("running as root: a read-only folder does not stop root's writes (and no mount(8))")
    made = subprocess.run(
        [mount, "-t", "tmpfs", "-o", "ro,size=64k", "tmpfs", str(where)], capture_output=True, text=True, check=False
    )
    if made.returncode != 0:
        pytest.skip(
            "running as root: a read-only folder does not stop root's writes "
            f"(and a read-only tmpfs cannot be mounted: {made.stderr.strip() or 'not permitted'})"
        )
    try:
        yield where
    finally:
        subprocess.run([umount, "-l", str(where)], capture_output=True, check=False)
