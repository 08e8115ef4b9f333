"""How the authoring tools save on Ctrl+S: a failed write is a line, never the end of the session.

The writes themselves are atomic and verified (:mod:`engine.atomic`); what this adds is the
tools' side of the contract: the unsaved work stays open in the scene, and when its file
refuses the save (a full disk, a read-only folder, a folder in the way) the same files are
written to the user's recovery folder instead (:mod:`engine.recovery`), whose path the
person is told in one line on screen and on the terminal. Ctrl+S again tries the file
first each time, so the save lands there once the disk is fixed.

One tool session (one process) keeps one recovery file per target, so pressing Ctrl+S
over and over does not fill the recovery folder; a later session never overwrites it.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path

from engine.recovery import Rescue

__all__ = ["save_or_say"]

_RESCUES: dict[Path, Rescue] = {}  # this process's recovery file of each target


def save_or_say(save: Callable[[Path], object], target: Path) -> str:
    """Run ``save(path)`` at ``target`` (else in the recovery folder); the line to show.

    The line is ``saved TARGET``, or why not and where the work went instead (also printed
    to stderr), or that it is still only open.
    """
    rescue = _RESCUES.setdefault(Path(target), Rescue(Path(target)))
    saved = rescue.save(save)
    if not saved.why:
        return f"saved {target}"
    if saved.path is not None:
        line = f"NOT saved to {target}: {saved.why}; saved instead to {saved.path} (open that file to go on)"
    else:
        line = (
            f"NOT saved: {saved.why} (the work is still open: Ctrl+S again once fixed, or restart with -o OTHER_FILE)"
        )
    print(line, file=sys.stderr)
    return line
