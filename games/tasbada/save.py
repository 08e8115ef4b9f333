"""Quest progress on disk: saved atomically, resumed through the restart menu.

What is kept is what a person would hate to redo — the marks on their photo, the
floor line, the stages reached and the photo path — as a small versioned JSON file,
replaced atomically (:func:`engine.atomic.atomic_write_bytes`), so a crash mid-save
leaves the previous progress intact. A damaged or foreign file is reported and set
aside (renamed ``*.bad``), never silently overwritten.

Where: ``$TASBADA_SAVE`` if set, else ``$XDG_DATA_HOME/puppetphone/tasbada.json``
(``~/.local/share/...``). Replays do not touch the default save — a demo must not
wipe someone's journey — unless ``$TASBADA_SAVE`` names a file explicitly.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path

from engine.atomic import atomic_write_bytes
from games.tasbada.quest import STAGES, Mark, Quest

__all__ = ["SAVE_VERSION", "SaveError", "Progress", "default_save_path", "save_progress", "load_progress",
           "progress_of"]

SAVE_VERSION = 1


class SaveError(ValueError):
    """The save file exists but cannot be read as Tasbada progress."""


@dataclass
class Progress:
    """What a save file holds."""

    reached: list[str]
    marks: list[Mark]
    ground_v: float
    stage: str
    photo: str = ""


def default_save_path() -> Path:
    """``$TASBADA_SAVE``, else the per-user data folder."""
    env = os.environ.get("TASBADA_SAVE")
    if env:
        return Path(env)
    base = os.environ.get("XDG_DATA_HOME") or str(Path.home() / ".local" / "share")
    return Path(base) / "puppetphone" / "tasbada.json"


def progress_of(q: Quest, photo: str = "") -> Progress:
    """The progress to save from the quest state (stages reached now and before)."""
    reached = [s for s in STAGES if s in q.reached or s in q.saved_reached]
    return Progress(reached, list(q.marks), q.ground_v, q.stage, photo)


def save_progress(path: str | os.PathLike[str], progress: Progress) -> Path:
    """Write ``progress`` to ``path`` atomically."""
    data = {"format": "tasbada-progress", "version": SAVE_VERSION, "reached": progress.reached,
            "stage": progress.stage, "ground_v": round(progress.ground_v, 6),
            "marks": [m.to_json() for m in progress.marks], "photo": progress.photo}
    return atomic_write_bytes(path, json.dumps(data, indent=1).encode())


def load_progress(path: str | os.PathLike[str]) -> Progress | None:
    """The progress in ``path``; ``None`` if there is none; :class:`SaveError` if it is damaged."""
    p = Path(path)
    if not p.exists():
        return None
    try:
        data = json.loads(p.read_text(encoding="utf-8"))
        if not isinstance(data, dict) or data.get("format") != "tasbada-progress":
            raise SaveError(f"{p} is not a Tasbada save file")
        if data.get("version") != SAVE_VERSION:
            raise SaveError(f"{p} has save version {data.get('version')!r}; this build reads {SAVE_VERSION}")
        reached = [s for s in data["reached"] if s in STAGES]
        marks = [Mark.from_json(m) for m in data["marks"]]
        ground_v = float(data["ground_v"])
        if not 0.0 <= ground_v <= 1.0:
            raise SaveError(f"{p}: floor line {ground_v} is off the image")
        stage = str(data.get("stage", reached[-1] if reached else STAGES[0]))
        return Progress(reached or [STAGES[0]], marks, ground_v, stage, str(data.get("photo", "")))
    except SaveError:
        raise
    except (OSError, UnicodeDecodeError, json.JSONDecodeError, KeyError, TypeError, ValueError) as exc:
        raise SaveError(f"{p} is damaged: {exc}") from exc
