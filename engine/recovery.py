"""When a save cannot go where it was asked to, it goes to the user's recovery folder instead.

A full disk, a read-only folder or a folder in the way makes :func:`engine.atomic.atomic_write_bytes`
refuse a save (the old file stays intact). The session keeps running and keeps the work in
memory, but a person about to quit would still lose it, and a game cannot ask for a new path
in the middle of play. So every interactive save (snowman F5, the tasbada progress, Ctrl+S
in the authoring tools, a growing ``--record``) goes through a :class:`Rescue`: the save is
tried at its own place first, every time (F5/Ctrl+S again retries it once the disk is
fixed), and when that fails the same bytes are written to :func:`recovery_folder`
(``$XDG_DATA_HOME/puppetphone/recovered``), whose path the game shows in one line. The
recovered file is the same kind of file, so it opens with the same option (``--set
field=PATH``, ``author edit PATH``, ``replay PATH``).

Recovered files are never overwritten by a later session: each :class:`Rescue` picks a free
name once (``walk.ppclip``, ``walk.1.ppclip`` …) and keeps writing its session's saves there.
When the recovery folder fails too (the same full disk), the line says so and the work is
still in memory for the next try.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

__all__ = ["Rescue", "Saved", "free_recovery_path", "recovery_folder"]


def recovery_folder() -> Path:
    """``$XDG_DATA_HOME/puppetphone/recovered`` (``~/.local/share/...`` without it)."""
    base = os.environ.get("XDG_DATA_HOME") or str(Path.home() / ".local" / "share")
    return Path(base) / "puppetphone" / "recovered"


def free_recovery_path(name: str, avoid: Path | None = None) -> Path:
    """A name in the recovery folder that no earlier recovered file has (``a.json``, ``a.1.json`` …), not ``avoid``."""
    folder = recovery_folder()
    stem, suffix = os.path.splitext(name)
    for n in range(10_000):
        candidate = folder / (name if n == 0 else f"{stem}.{n}{suffix}")
        if candidate != avoid and not os.path.lexists(candidate):
            return candidate
    return folder / f"{stem}.{os.getpid()}{suffix}"  # ten thousand recoveries of one name: the process's own


@dataclass
class Saved:
    """Where a save went: ``path`` (``None`` when nowhere) and, if not its own place, ``why`` not."""

    path: Path | None
    why: str = ""

    @property
    def recovered(self) -> bool:
        """Saved, but in the recovery folder instead of where it was asked to go."""
        return self.path is not None and bool(self.why)

    def line(self, what: str, target: Path) -> str:
        """One line for the terminal: saved, recovered elsewhere, or not saved at all."""
        if not self.why:
            return f"{what} saved to {target}"
        if self.path is not None:
            return f"{what} NOT saved to {target} ({self.why}); saved instead to {self.path}"
        return f"{what} NOT saved ({self.why}); the work is still open: save again once fixed"


@dataclass
class Rescue:
    """Saves to ``target``, and to one file of the recovery folder whenever ``target`` refuses."""

    target: Path
    recovered: Path | None = None

    def save(self, write: Callable[[Path], object]) -> Saved:
        """``write(path)`` at the target, else at the recovery path; what happened.

        ``write`` raises ``OSError`` (a :class:`~engine.atomic.WriteError`) or ``ValueError``
        (a path its format refuses) when it saves nothing.
        """
        try:
            write(self.target)
            return Saved(self.target)
        except (OSError, ValueError) as exc:
            why = str(exc)
        if self.recovered is None:
            self.recovered = free_recovery_path(self.target.name, avoid=self.target)
        try:
            write(self.recovered)
        except (OSError, ValueError) as exc:
            return Saved(None, f"{why}; and in {self.recovered.parent}: {exc}")
        return Saved(self.recovered, why)
