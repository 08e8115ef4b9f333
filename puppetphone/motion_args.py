"""Command-line options for motion files, shared by every command that reads or writes them.

``cycle``, ``cycles``, ``clips add`` and ``author edit`` take the same input options
(``--animation``, ``--units`` or ``--height``, ``--up``, ``--joint-map``), and commands that write loops the same
export options (``--fps``, ``--closing-frame``); defining them once keeps their spelling
and help identical. The values go to :func:`engine.io.motion_file.load_motion` and
:func:`authoring.cycles.formats.save_loop`.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

__all__ = [
    "UNIT_NAMES",
    "UP_AXES",
    "about",
    "add_export_options",
    "add_motion_options",
    "export_options",
    "motion_options",
]

# The choices of ``--units`` and ``--up``, spelled here so parsing imports neither numpy nor the readers
# (a test checks them against ``engine.io.units.UNITS`` and ``engine.io.up_axis.AXES``).
UNIT_NAMES = ("m", "cm", "mm", "in", "cmu")
UP_AXES = ("x", "-x", "y", "-y", "z", "-z")


def add_motion_options(parser: argparse.ArgumentParser) -> None:
    """``--animation``, ``--units``, ``--height``, ``--up`` and ``--joint-map``."""
    parser.add_argument(
        "--animation", metavar="NAME|INDEX", help="glTF/GLB: which animation (name or 0-based index; default the first)"
    )
    parser.add_argument(
        "--units",
        choices=UNIT_NAMES,
        help="length unit of a BVH/glTF file (default: judged by the figure's leg length or size; "
        "cmu = the CMU database's 1/0.45 inch; a figure no unit fits is scaled to an adult's "
        "size and says so)",
    )
    parser.add_argument(
        "--height",
        type=float,
        metavar="METRES",
        help="instead of --units: scale the figure so it stands this tall (any size, not a unit's)",
    )
    parser.add_argument(
        "--up",
        choices=UP_AXES,
        metavar="AXIS",
        help="the file's up axis: x, y, z, -x, -y or -z (write --up=-z); default judged by the figure "
        "(a Blender export keeps z up); the figure is stood up with it",
    )
    parser.add_argument(
        "--joint-map",
        metavar="FILE",
        help="JSON object of source joint name -> puppet joint name, for a skeleton no built-in map fits",
    )


def add_export_options(parser: argparse.ArgumentParser) -> None:
    """``--fps`` and ``--closing-frame`` / ``--no-closing-frame`` for loops written to BVH/glTF."""
    parser.add_argument(
        "--fps",
        type=float,
        metavar="N",
        help="frame rate of a BVH/glTF loop (default: the source's nominal rate); the loop is "
        "resampled to a whole number of frames at exactly this rate (it stretches by under "
        "half a frame)",
    )
    parser.add_argument(
        "--closing-frame",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="repeat the first pose at the end of a BVH loop, so Blender's Cycles modifier "
        "loops without skipping a pose (default: on for BVH)",
    )


def motion_options(args: argparse.Namespace) -> dict[str, Any]:
    """Keyword arguments of ``load_motion`` from parsed options (the joint map file is read here)."""
    from engine.io.motion_file import load_joint_map

    joint_map = getattr(args, "joint_map", None)
    return {
        "animation": getattr(args, "animation", None),
        "units": getattr(args, "units", None),
        "height": getattr(args, "height", None),
        "up": getattr(args, "up", None),
        "joint_map": load_joint_map(joint_map) if joint_map else None,
    }


def export_options(args: argparse.Namespace) -> dict[str, Any]:
    """Keyword arguments of ``save_loop`` from parsed options."""
    fps = getattr(args, "fps", None)
    if fps is not None and not 0 < fps <= 1000:
        raise ValueError(f"--fps must be in (0, 1000], got {fps:g}")
    return {"fps": fps, "closing_frame": getattr(args, "closing_frame", None)}


def about(path: object, error: BaseException) -> str:
    """``"PATH: why"``, without naming the file twice when the reader's message already names it."""
    message, name = str(error), str(path)
    return message if Path(name).name in message else f"{name}: {message}"
