"""The options every session shares (``--headless --frames --screenshot --size``), parsed once.

Values are checked by argparse types, so a wrong one stops the command before anything
starts, with the sub-command's usage and one line saying what is wrong.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from engine.render.target import image_format
from engine.runner import RunOptions

__all__ = ["add_run_arguments", "run_options", "steps", "window_size", "image_path", "MAX_SIZE"]

#: The largest window or image side accepted (a 16k display is 15360 wide).
MAX_SIZE = 16384


def steps(text: str) -> int:
    """A number of simulation steps: zero or more."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
    if value < 0:
        raise argparse.ArgumentTypeError(f"{value} is negative; give zero or more steps")
    return value


def window_size(text: str) -> tuple[int, int]:
    """``WxH`` in pixels, each side from 16 to :data:`MAX_SIZE`."""
    try:
        width, height = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} does not look like 1280x720") from None
    if not (16 <= width <= MAX_SIZE and 16 <= height <= MAX_SIZE):
        raise argparse.ArgumentTypeError(f"{width}x{height} is out of range: each side from 16 to {MAX_SIZE}")
    return width, height


def image_path(text: str) -> Path:
    """A screenshot or plot file: ``.png`` or ``.jpg``, refused before the session starts."""
    try:
        image_format(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    return Path(text)


def add_run_arguments(parser: argparse.ArgumentParser, *, screenshot_at: bool = False) -> None:
    """Add the shared session options to a sub-command."""
    parser.add_argument("--headless", action="store_true",
                        help="no window: render off-screen (EGL), for servers, tests and screenshots")
    parser.add_argument("--frames", type=steps, default=None, metavar="N", help="stop after N simulation steps")
    parser.add_argument("--screenshot", type=image_path, default=None, metavar="IMAGE",
                        help="write the last frame as PNG or JPEG (by suffix)")
    if screenshot_at:
        parser.add_argument("--screenshot-at", type=steps, default=None, metavar="N",
                            help="take the screenshot after step N instead of at the end")
    parser.add_argument("--size", type=window_size, default=(1280, 720), metavar="WxH",
                        help="window or image size (default 1280x720)")


def run_options(args: argparse.Namespace, title: str, *, pace: bool = False) -> RunOptions:
    """The runner's options from parsed arguments."""
    width, height = args.size
    return RunOptions(headless=args.headless, frames=args.frames, screenshot=args.screenshot,
                      screenshot_at=getattr(args, "screenshot_at", None), width=width, height=height,
                      title=title, pace=pace)
