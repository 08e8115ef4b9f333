"""The options every session shares (``--headless --frames --screenshot --size --quality``), parsed once.

Values are checked by argparse types, so a wrong one stops the command before anything
starts, with the sub-command's usage and one line saying what is wrong.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path
from typing import TYPE_CHECKING

from puppetphone.argtypes import MAX_WINDOW, int_range, output_file, window_size

if TYPE_CHECKING:  # the engine's modules load numpy and GL: imported when a session starts, not to parse
    from engine.runner import RunOptions

__all__ = ["HUD_DUMP_ENV", "QUALITY_NAMES", "add_run_arguments", "image_path", "quality_name", "run_options", "steps"]

#: Steps: zero or more.
steps = int_range(0)


def image_path(text: str) -> Path:
    """A screenshot or plot file to write: ``.png`` or ``.jpg``, refused before the session starts."""
    from engine.render.target import image_format

    path = output_file(text)
    try:
        image_format(path)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    return path


#: ``engine.render.quality.QUALITY_NAMES``, spelled here so that parsing (the default ``auto`` too)
#: does not import the renderer (a second of imports; a test checks the two agree).
QUALITY_NAMES = ("low", "medium", "high", "auto")


def quality_name(text: str) -> str:
    """A ``--quality`` value, refused before the session starts when it is none of the levels
    (as :func:`engine.render.quality.parse_quality` does)."""
    name = text.strip().lower()
    if name not in QUALITY_NAMES:
        raise argparse.ArgumentTypeError(f"quality must be one of {', '.join(QUALITY_NAMES)}, not {text!r}")
    return name


def add_run_arguments(parser: argparse.ArgumentParser, *, screenshot_at: bool = False) -> None:
    """Add the shared session options to a sub-command."""
    parser.add_argument(
        "--headless", action="store_true", help="no window: render off-screen (EGL), for servers, tests and screenshots"
    )
    parser.add_argument("--frames", type=steps, default=None, metavar="N", help="stop after N simulation steps")
    parser.add_argument(
        "--screenshot",
        type=image_path,
        default=None,
        metavar="IMAGE",
        help="write the last frame as PNG or JPEG (by suffix)",
    )
    if screenshot_at:
        parser.add_argument(
            "--screenshot-at",
            type=steps,
            default=None,
            metavar="N",
            help="take the screenshot after step N instead of at the end",
        )
    parser.add_argument(
        "--size",
        type=window_size,
        default=(1280, 720),
        metavar="WxH",
        help=f"window or image size, sides up to {MAX_WINDOW} (default 1280x720)",
    )
    parser.add_argument(
        "--quality",
        type=quality_name,
        default="auto",
        metavar="LEVEL",
        help="drawing quality: low, medium, high or auto (default: chosen from the measured "
        "frame time in a window, high headless; G changes it while playing)",
    )


#: The environment variable that names a file for the HUD's text (``RunOptions.hud_dump``).
HUD_DUMP_ENV = "PUPPETPHONE_HUD_DUMP"


def run_options(args: argparse.Namespace, title: str, *, pace: bool = False) -> RunOptions:
    """The runner's options from parsed arguments (and ``$PUPPETPHONE_HUD_DUMP``)."""
    from engine.runner import RunOptions

    width, height = args.size
    hud = os.environ.get(HUD_DUMP_ENV)
    return RunOptions(
        headless=args.headless,
        frames=args.frames,
        screenshot=args.screenshot,
        screenshot_at=getattr(args, "screenshot_at", None),
        width=width,
        height=height,
        title=title,
        pace=pace,
        hud_dump=Path(hud) if hud else None,
        quality=getattr(args, "quality", "auto"),
    )
