"""Shared by the window tests: a real X server (Xvfb) on a display number nobody uses (the fixture `display`)."""

from __future__ import annotations

import os
import shutil
import subprocess
from collections.abc import Iterator

import pytest

needs_x = pytest.mark.skipif(
    not (shutil.which("Xvfb") and shutil.which("import")),
    reason="needs Xvfb and ImageMagick's import (Debian xvfb imagemagick)",
)

SCREEN = (1280, 800)


@pytest.fixture(scope="module")
def display() -> Iterator[str]:
    """A fresh Xvfb display; its name. Xvfb picks a free number itself and writes it once it accepts
    connections (``-displayfd``), so tests running in parallel (pytest -n) never race for one.

    ``-noreset``: by default an X server resets when its last client leaves, and drops every client
    still connecting at that moment. A test polls with short-lived clients (``xdotool search``) while
    the program it started opens its window, so one of those leaving just as the program connected
    made the program fail with "x11 not available" (more often on a loaded machine, where each step
    takes longer); tests/puppetphone/test_xvfb.py checks that a connecting client outlives it."""
    read_end, write_end = os.pipe()
    server = subprocess.Popen(
        [
            "Xvfb",
            "-displayfd",
            str(write_end),
            "-screen",
            "0",
            f"{SCREEN[0]}x{SCREEN[1]}x24",
            "-nolisten",
            "tcp",
            "-noreset",
        ],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        pass_fds=(write_end,),
    )
    os.close(write_end)
    with os.fdopen(read_end) as announced:
        number = announced.readline().strip()
    assert number.isdigit() and server.poll() is None, "Xvfb did not start"
    yield f":{number}"
    server.terminate()
    server.wait(10)
