"""Quest progress on disk: saved atomically, resumed through the restart menu.

What is kept is what a person would hate to redo — the marks on their photo, the
floor line, the stages reached and the photo path — as a small versioned JSON file,
replaced atomically (:func:`engine.atomic.atomic_write_bytes`), so a crash mid-save
leaves the previous progress intact. :func:`load_progress` is the format's validation
boundary: only a regular file of at most :data:`MAX_FILE` bytes is read (a pipe or a
device is refused, never waited on or streamed), and every value is type- and
range-checked before use. A damaged save of ours is reported and set aside (renamed
``*.bad``); a path holding anything else (a folder, a device, a user's file) is left
alone and never overwritten (:data:`SAVE_HEADS`).

Where: ``$TASBADA_SAVE`` if set, else ``$XDG_DATA_HOME/puppetphone/tasbada.json``
(``~/.local/share/...``). Replays do not touch the default save — a demo must not
wipe someone's journey — unless ``$TASBADA_SAVE`` names a file explicitly.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from engine.atomic import atomic_write_bytes
from engine.errors import FormatError
from engine.npz_safe import read_bounded
from games.tasbada.quest import STAGES, Mark, Quest

__all__ = [
    "SAVE_VERSION",
    "SaveError",
    "Progress",
    "default_save_path",
    "save_progress",
    "load_progress",
    "progress_of",
    "checked_progress",
    "SAVE_HEADS",
    "MAX_FILE",
]

SAVE_VERSION = 1
#: A real save is a few KB (a few marks of a few hundred points).
MAX_FILE = 1 << 20
MAX_MARKS = 64
MAX_POINTS = 4096
MAX_PATH = 4096
#: How every save this program writes begins: only such a file is set aside or replaced.
SAVE_HEADS = (b'{\n "format": "tasbada-progress"',)


class SaveError(FormatError):
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
    """Write ``progress`` to ``path`` atomically (never over a file that is not a save of ours).

    Raises:
        WriteError: nothing was written (full disk, folder in the way, a foreign file).
    """
    data = {
        "format": "tasbada-progress",
        "version": SAVE_VERSION,
        "reached": progress.reached,
        "stage": progress.stage,
        "ground_v": round(progress.ground_v, 6),
        "marks": [m.to_json() for m in progress.marks],
        "photo": progress.photo,
    }
    return atomic_write_bytes(path, json.dumps(data, indent=1).encode(), expect_head=SAVE_HEADS)


def _is_number(x: object) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def checked_progress(reached: Any, marks: Any, ground_v: Any) -> tuple[list[str], list[Mark], float | None]:
    """The stages reached, the marks and the floor line, every value checked (saves and recordings).

    Raises:
        SaveError: a value of the wrong type, out of range, or more of them than a save holds.
    """
    if not isinstance(reached, list) or len(reached) > 4 * len(STAGES) or not all(isinstance(s, str) for s in reached):
        raise SaveError("reached must be a short list of stage names")
    if not isinstance(marks, list) or len(marks) > MAX_MARKS:
        raise SaveError(f"marks must be a list of at most {MAX_MARKS} marks")
    checked = []
    for m in marks:
        points = m.get("points") if isinstance(m, dict) else None
        if (
            not isinstance(points, list)
            or len(points) > MAX_POINTS
            or not all(isinstance(p, list) and len(p) == 2 and all(map(_is_number, p)) for p in points)
        ):
            raise SaveError(f"a mark must have at most {MAX_POINTS} points of two numbers each")
        try:
            checked.append(Mark.from_json(m))
        except (ValueError, TypeError, OverflowError) as exc:
            raise SaveError(str(exc)[:200]) from None
    if ground_v is not None and (not _is_number(ground_v) or not 0.0 <= ground_v <= 1.0):
        raise SaveError(f"floor line {repr(ground_v)[:30]} is not a number on the image (0..1)")
    return [s for s in reached if s in STAGES], checked, None if ground_v is None else float(ground_v)


def load_progress(path: str | os.PathLike[str]) -> Progress | None:
    """The progress in ``path``; ``None`` if there is none; :class:`SaveError` if it is damaged or not a save."""
    p = Path(path)
    try:
        raw = read_bounded(p, MAX_FILE)
    except FileNotFoundError:
        return None
    except OSError as exc:
        raise SaveError(f"{p}: {exc.strerror or exc}") from None
    except ValueError as exc:  # a folder, a pipe, a device, or too big
        raise SaveError(str(exc)) from None
    try:
        data = json.loads(raw.decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise SaveError(f"{p} is damaged: {exc}"[:300]) from None
    except RecursionError:
        raise SaveError(f"{p} is damaged: JSON nested too deeply") from None
    if not isinstance(data, dict) or data.get("format") != "tasbada-progress":
        raise SaveError(f"{p} is not a Tasbada save file")
    if data.get("version") != SAVE_VERSION:
        raise SaveError(f"{p} has save version {repr(data.get('version'))[:20]}; this build reads {SAVE_VERSION}")
    try:
        reached, marks, ground_v = checked_progress(data.get("reached"), data.get("marks"), data.get("ground_v"))
        if ground_v is None:
            raise SaveError("the floor line is missing")
    except SaveError as exc:
        raise SaveError(f"{p} is damaged: {exc}") from None
    stage, photo = data.get("stage", reached[-1] if reached else STAGES[0]), data.get("photo", "")
    if not isinstance(stage, str) or not isinstance(photo, str) or len(photo) > MAX_PATH:
        raise SaveError(f"{p} is damaged: stage and photo must be text")
    return Progress(reached or [STAGES[0]], marks, ground_v, stage, photo)
