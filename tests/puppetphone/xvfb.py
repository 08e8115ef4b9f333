"""Shared by the window tests: a real X server (Xvfb) on a display number nobody uses (the fixture `display`)."""

from __future__ import annotations

import shutil
import subprocess
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

needs_x = pytest.mark.skipif(not (shutil.which("Xvfb") and shutil.which("import")),
                             reason="needs Xvfb and ImageMagick's import (Debian xvfb imagemagick)")

SCREEN = (1280, 800)


def _accepts(path: Path) -> bool:
    """Whether the X server takes connections on its Unix socket."""
    import socket

    with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as probe:
        try:
            probe.connect(str(path))
        except OSError:
            return False
    return True


@pytest.fixture(scope="module")
def display() -> Iterator[str]:
    """A fresh Xvfb display; its name."""
    for number in range(91, 120):
        if not Path(f"/tmp/.X11-unix/X{number}").exists() and not Path(f"/tmp/.X{number}-lock").exists():
            break
    name = f":{number}"
    server = subprocess.Popen(["Xvfb", name, "-screen", "0", f"{SCREEN[0]}x{SCREEN[1]}x24", "-nolisten", "tcp"],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 20
    while not _accepts(Path(f"/tmp/.X11-unix/X{number}")):  # the socket file comes before the server listens
        assert server.poll() is None and time.monotonic() < deadline, "Xvfb did not start"
        time.sleep(0.1)
    yield name
    server.terminate()
    server.wait(10)
