"""A clip library: a folder of ``.ppclip`` files and a manifest of their roles.

The folder (default ``$XDG_DATA_HOME/puppetphone/clips``, i.e.
``~/.local/share/puppetphone/clips``) holds one conformed clip per role
(``walk.ppclip``…) and ``clips.json``::

    {"format": "puppetphone-clips", "version": 1,
     "clips": {"walk": {"file": "walk.ppclip", "sha256": "…", "source": "cmu_16_15_walk_daz.bvh"}}}

The manifest is the one validation boundary of the folder: a manifest that is not
this shape, a clip file missing or changed behind its back (its content hash no longer
the recorded one) is refused in one line by :class:`ClipLibraryError`. Every write
(manifest and clips) is atomic, and a clip is written before the manifest names it,
so an interrupted ``clips add`` never leaves the library naming a missing file. A new
clip for a role that already has one never goes over the file the manifest names: it is
written under the role's other name (``walk.ppclip`` / ``walk.1.ppclip`` in turn) and the
old file is removed only after the manifest names the new one, so a kill at any point
leaves a library that loads (the old clip or the new one, never a mismatch).
"""

from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from engine.atomic import atomic_write_bytes
from engine.clip import Clip
from engine.clipfile import ClipFileError, load_clip, save_clip
from engine.cliplib.roles import RoleError, check_role, check_set, normalise_role
from engine.errors import FormatError
from engine.skeleton import Skeleton

__all__ = [
    "ClipLibrary",
    "ClipLibraryError",
    "Entry",
    "default_library_dir",
    "clip_digest",
    "set_digest",
    "MANIFEST",
    "FORMAT",
    "VERSION",
]

MANIFEST = "clips.json"
FORMAT = "puppetphone-clips"
VERSION = 1
_MAX_MANIFEST = 1 << 20


class ClipLibraryError(FormatError):
    """A library that cannot be used: a damaged manifest, a missing or altered clip, a refused role."""


def default_library_dir() -> Path:
    """``$XDG_DATA_HOME/puppetphone/clips`` (``~/.local/share/puppetphone/clips`` when unset)."""
    base = os.environ.get("XDG_DATA_HOME") or str(Path.home() / ".local" / "share")
    return Path(base) / "puppetphone" / "clips"


def clip_digest(clip: Clip) -> str:
    """SHA-256 of everything about a clip that changes how it plays (independent of file bytes)."""
    h = hashlib.sha256()
    meta = {
        "name": clip.name,
        "fps": clip.fps,
        "loop": clip.loop,
        "markers": dict(sorted(clip.markers.items())),
        "joints": list(clip.skeleton.names),
        "parents": [int(p) for p in clip.skeleton.parents],
    }
    h.update(json.dumps(meta, sort_keys=True).encode())
    arrays = [clip.root, clip.rotations, clip.skeleton.offsets, clip.skeleton.tips, clip.skeleton.radii]
    if clip.root_motion is not None:
        arrays += [clip.root_motion.translation, clip.root_motion.heading]
    for a in arrays:
        b = np.ascontiguousarray(a, dtype=np.float64)
        h.update(str(b.shape).encode() + b.tobytes())
    return h.hexdigest()


def set_digest(clips: Mapping[str, Clip]) -> str:
    """One hash for a set of clips by role: what a recording stores and the lookup cache is keyed by."""
    h = hashlib.sha256()
    for role in sorted(clips):
        h.update(role.encode() + b"\0" + clip_digest(clips[role]).encode())
    return h.hexdigest()


@dataclass(frozen=True)
class Entry:
    """One manifest line: a role, its file (relative to the folder), content hash and where it came from."""

    role: str
    file: str
    sha256: str
    source: str = ""


def _entries(raw: object, where: Path) -> dict[str, Entry]:
    if not isinstance(raw, dict) or raw.get("format") != FORMAT:
        raise ClipLibraryError(f"{where} is not a {FORMAT} manifest")
    version = raw.get("version")
    if not isinstance(version, int) or isinstance(version, bool) or not 1 <= version <= VERSION:
        raise ClipLibraryError(f"{where}: manifest version {repr(version)[:20]}; this build reads 1..{VERSION}")
    clips = raw.get("clips")
    if not isinstance(clips, dict):
        raise ClipLibraryError(f"{where}: 'clips' must map roles to entries")
    out = {}
    for role, e in clips.items():
        ok = isinstance(e, dict) and all(isinstance(e.get(k), str) for k in ("file", "sha256"))
        if not ok or not isinstance(e.get("source", ""), str):
            raise ClipLibraryError(f"{where}: the entry of {str(role)[:40]!r} needs 'file' and 'sha256' strings")
        try:
            name = normalise_role(str(role))
        except RoleError as exc:
            raise ClipLibraryError(f"{where}: {exc}") from None
        file = e["file"]
        if Path(file).name != file or not file.endswith(".ppclip"):
            raise ClipLibraryError(f"{where}: {role!r} names {file[:60]!r}; a library clip is a .ppclip in the folder")
        out[name] = Entry(name, file, e["sha256"], e.get("source", ""))
    return out


class ClipLibrary:
    """The folder at ``root`` (it need not exist: a missing or empty library has no clips)."""

    def __init__(self, root: str | Path) -> None:
        self.root = Path(root)

    @property
    def manifest_path(self) -> Path:
        return self.root / MANIFEST

    def entries(self) -> dict[str, Entry]:
        """The manifest's entries by role (none when there is no manifest)."""
        path = self.manifest_path
        if not path.exists():
            return {}
        try:
            data = path.read_bytes()[: _MAX_MANIFEST + 1]
        except OSError as exc:
            raise ClipLibraryError(f"cannot read {path}: {exc.strerror or exc}") from None
        if len(data) > _MAX_MANIFEST:
            raise ClipLibraryError(f"{path} is larger than {_MAX_MANIFEST} bytes; not a clip manifest")
        try:
            raw = json.loads(data.decode())
        except (UnicodeDecodeError, json.JSONDecodeError, RecursionError):
            raise ClipLibraryError(f"{path} is not valid JSON") from None
        return dict(sorted(_entries(raw, path).items()))

    def load(self) -> dict[str, Clip]:
        """Every clip by role, each checked against the hash the manifest recorded."""
        out = {}
        for role, e in self.entries().items():
            try:
                clip = load_clip(self.root / e.file)
            except (ClipFileError, OSError) as exc:
                raise ClipLibraryError(f"library {self.root}: {role}: {exc}") from None
            if clip_digest(clip) != e.sha256:
                raise ClipLibraryError(
                    f"library {self.root}: {e.file} changed since it was added as the {role}; "
                    f"add it again (puppetphone clips add … --role {role})"
                )
            out[role] = clip
        return out

    def raw_manifest(self) -> dict[str, object]:
        """The manifest as JSON (empty without one): what the entries and the ``character`` entry are read from."""
        if not self.manifest_path.exists():
            return {}
        self.entries()  # the checks: size, JSON, format
        raw = json.loads(self.manifest_path.read_bytes().decode())
        return raw if isinstance(raw, dict) else {}

    def _write_manifest(self, entries: Mapping[str, Entry], character: object = None, keep: bool = True) -> None:
        """Write the entries; the ``character`` entry (:mod:`engine.cliplib.character`) is kept unless given or dropped."""
        clips = {r: {"file": e.file, "sha256": e.sha256, "source": e.source} for r, e in sorted(entries.items())}
        body: dict[str, object] = {"format": FORMAT, "version": VERSION, "clips": clips}
        if character is None and keep:
            character = self.raw_manifest().get("character")
        if character is not None:
            body["character"] = character
        atomic_write_bytes(self.manifest_path, (json.dumps(body, indent=2) + "\n").encode())

    def add(self, clip: Clip, role: str, skeleton: Skeleton, defaults: Mapping[str, Clip], source: str = "") -> Entry:
        """Check ``clip`` (already conformed) for ``role`` and against the rest of the set, then store it.

        ``defaults`` are the built-in clips that fill the roles the library leaves empty,
        so the set check (a walk slower than the run…) sees what will really play.
        """
        role = normalise_role(role)
        try:
            check_role(clip, role, skeleton)
            check_set({**defaults, **self.load(), role: clip})
        except RoleError as exc:
            raise ClipLibraryError(str(exc)) from None
        entries = self.entries()
        self.root.mkdir(parents=True, exist_ok=True)
        old = entries.get(role)
        file = f"{role}.1.ppclip" if old is not None and old.file == f"{role}.ppclip" else f"{role}.ppclip"
        save_clip(clip, self.root / file)
        # The digest of what a load gives back (reading renormalises rotations, to the last bit).
        entry = Entry(role, file, clip_digest(load_clip(self.root / file)), source)
        entries[role] = entry
        self._write_manifest(entries)
        if old is not None and old.file != file:
            (self.root / old.file).unlink(missing_ok=True)
        return entry

    def remove(self, role: str) -> Entry:
        """Take ``role`` out of the manifest and delete its file; the built-in clip plays it again."""
        role = normalise_role(role)
        entries = self.entries()
        if role not in entries:
            known = ", ".join(entries) or "none"
            raise ClipLibraryError(f"library {self.root} has no {role} (roles in it: {known})")
        entry = entries.pop(role)
        self._write_manifest(entries)
        (self.root / entry.file).unlink(missing_ok=True)
        return entry
