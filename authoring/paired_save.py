"""A clip and its side file, saved as a pair that a kill between the two writes cannot break.

The editors keep what a clip file cannot hold (MoCurves' pins and scales, a keyframed clip's
Bézier keys) in a side file that names the clip it belongs to by checksum. The two files are
two atomic writes, so the side file goes first and also keeps the entry of the clip still on
disk (``previous``): cut between the writes, the old clip still opens with its own entry; after
both, the new one does. A reader looks its clip's entry up with :func:`entry_for`.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from engine.atomic import atomic_write_bytes

__all__ = ["entry_for", "write_pair"]


def entry_for(side: Any, digest: str) -> dict[str, Any] | None:
    """The side file's entry for the clip with ``digest``: its own, or the one it kept of the clip before."""
    if not isinstance(side, dict):
        return None
    for entry in (side, side.get("previous")):
        if isinstance(entry, dict) and entry.get("clip_sha256") == digest:
            return {k: v for k, v in entry.items() if k != "previous"}
    return None


def write_pair(
    clip_path: Path, data: bytes, side_file: Path, side: dict[str, Any], before: dict[str, Any] | None
) -> Path:
    """Write ``side`` (carrying ``before``, the entry the clip on disk opens with, when it differs), then the clip."""
    if before is not None and before.get("clip_sha256") != side.get("clip_sha256"):
        side = {**side, "previous": before}
    atomic_write_bytes(side_file, json.dumps(side).encode())
    return atomic_write_bytes(clip_path, data)
