"""The window tests' X server (:func:`tests.puppetphone.xvfb.display`) keeps a client that is still
connecting when the last connected one leaves.

Without ``-noreset`` Xvfb resets at that moment and drops the connecting client: the cause of
test_first_hour's "x11 not available" under load (an ``xdotool search`` poll leaving just as the
program it waits for opened its display). Here the race is made deterministic with two raw
connections: B connects and waits, A completes its set-up and leaves, then B asks for its set-up.
Broken once by taking ``-noreset`` out of the fixture: B's set-up then fails with a broken pipe.
"""

from __future__ import annotations

import shutil
import socket
import struct
import time

import pytest

pytestmark = pytest.mark.skipif(shutil.which("Xvfb") is None, reason="needs Xvfb (Debian xvfb)")


def _connect(display: str) -> socket.socket:
    s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    s.settimeout(10)
    s.connect(f"/tmp/.X11-unix/X{display.lstrip(':')}")
    return s


def _set_up(s: socket.socket) -> bytes:
    """The X11 connection set-up (little-endian, protocol 11.0, no authorisation); the reply's first
    byte (1: success), or b"" when the server closed the connection."""
    try:
        s.sendall(struct.pack("<cxHHHHxx", b"l", 11, 0, 0, 0))
        return s.recv(1)
    except (BrokenPipeError, ConnectionResetError):
        return b""


def test_a_client_connecting_as_the_last_one_leaves_is_served(display: str) -> None:
    connecting = _connect(display)
    try:
        last = _connect(display)
        assert _set_up(last) == b"\x01"
        time.sleep(0.2)  # the server has accepted both connections
        last.close()  # the only connected client leaves
        time.sleep(0.5)  # a resetting server would now close the connecting one
        assert _set_up(connecting) == b"\x01", "the X server dropped a client that was still connecting"
    finally:
        connecting.close()
