"""Argument types for the command line: each value checked once, where argparse reads it.

A bad value is refused by argparse itself, with the option's name and the reason on one
line and exit code 2, before anything is opened or started: no traceback from deep inside
a socket, a GL context or a file open. Each function takes the option's text and returns
the value or raises ``argparse.ArgumentTypeError``.
"""

from __future__ import annotations

import argparse
import stat
from collections.abc import Callable
from pathlib import Path

__all__ = ["port", "window_size", "int_range", "output_file", "take_position", "MAX_WINDOW"]

# Past this a window (and its GL framebuffers) is no screen's: 8K is 7680x4320.
MAX_WINDOW = 8192
MIN_WINDOW = 16


def _int(text: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None


def int_range(lo: int, hi: int | None = None) -> Callable[[str], int]:
    """A whole number from ``lo`` to ``hi`` (no upper bound if ``None``)."""

    def parse(text: str) -> int:
        v = _int(text)
        if v < lo or (hi is not None and v > hi):
            span = f"at least {lo}" if hi is None else f"from {lo} to {hi}"
            raise argparse.ArgumentTypeError(f"{v} is out of range: must be {span}")
        return v

    parse.__name__ = "int"  # argparse names the type in its messages
    return parse


def port(text: str) -> int:
    """A UDP/TCP port, 0..65535 (0: the system picks a free one)."""
    return int_range(0, 65535)(text)


def window_size(text: str) -> tuple[int, int]:
    """``WxH`` in pixels, each side from 16 to :data:`MAX_WINDOW`."""
    w, sep, h = text.lower().partition("x")
    if not sep:
        raise argparse.ArgumentTypeError(f"{text!r} must look like 1280x720")
    side = int_range(MIN_WINDOW, MAX_WINDOW)
    try:
        return side(w), side(h)
    except argparse.ArgumentTypeError as exc:
        raise argparse.ArgumentTypeError(f"{text!r}: {exc}") from None


def output_file(text: str) -> Path:
    """A file to write: its folder must exist, and it must not be a folder, a device or a pipe.

    An existing regular file is accepted (the command says it replaces it).
    """
    path = Path(text)
    if not text or text.endswith(("/", "\\")):
        raise argparse.ArgumentTypeError(f"{text!r} names a folder, not a file")
    parent = path.parent
    if not parent.is_dir():
        raise argparse.ArgumentTypeError(f"cannot write {text}: folder {str(parent)!r} does not exist")
    try:
        mode = path.stat().st_mode
    except FileNotFoundError:
        return path
    except OSError as exc:
        raise argparse.ArgumentTypeError(f"cannot write {text}: {exc.strerror}") from None
    if stat.S_ISDIR(mode):
        raise argparse.ArgumentTypeError(f"cannot write {text}: it is a folder")
    if not stat.S_ISREG(mode):
        raise argparse.ArgumentTypeError(f"cannot write {text}: it is not a regular file (a device or a pipe)")
    return path


def take_position(text: str) -> object:
    """A position in a take for ``--start/--end``: seconds (``4.0``, ``4.0s``) or a frame (``480f``)."""
    from authoring.cycles.take_range import parse_bound

    try:
        return parse_bound(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
