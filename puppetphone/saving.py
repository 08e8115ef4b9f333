"""How the authoring tools save on Ctrl+S: a failed write is a line, never the end of the session.

The writes themselves are atomic and verified (:mod:`engine.atomic`); what this adds is the
tools' side of the contract: the unsaved work stays open in the scene, the person is told
in one line on screen and on the terminal why it was not saved, and where else to save.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path

__all__ = ["save_or_say"]


def save_or_say(save: Callable[[], object], target: Path | None) -> str:
    """Run ``save()``; the line to show: ``saved TARGET``, or why not (also printed to stderr)."""
    try:
        save()
    except (OSError, ValueError) as exc:  # WriteError (disk full, folder in the way), or a path the format refuses
        line = f"NOT saved: {exc} (the work is still open: Ctrl+S again once fixed, or restart with -o OTHER_FILE)"
        print(line, file=sys.stderr)
        return line
    return f"saved {target}"
