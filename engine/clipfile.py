"""The clip file format (``.ppclip``): versioned, checksummed, written atomically.

A ``.ppclip`` is a zip (numpy ``.npz``) holding a JSON header and the arrays. The
header names the format and its version, the skeleton (names, parents, offsets,
tips, radii), fps, loop flag, markers, and a SHA-256 of the array bytes, so a
file that was truncated or altered is refused with a clear message rather than
loaded as garbage. Readers refuse versions newer than they know.
"""

from __future__ import annotations

import hashlib
import io
import json
import zipfile
from pathlib import Path
from typing import Any

import numpy as np

from engine.atomic import atomic_write
from engine.clip import Clip, RootMotion
from engine.skeleton import Skeleton

__all__ = ["save_clip", "load_clip", "ClipFileError", "FORMAT", "VERSION"]

FORMAT = "puppetphone-clip"
VERSION = 1


class ClipFileError(ValueError):
    """A clip file that cannot be read: corrupt, truncated, not a clip, or a newer version."""


def _digest(arrays: dict[str, np.ndarray]) -> str:
    h = hashlib.sha256()
    for key in sorted(arrays):
        a = np.ascontiguousarray(arrays[key])
        h.update(key.encode() + a.dtype.str.encode() + str(a.shape).encode() + a.tobytes())
    return h.hexdigest()


def save_clip(clip: Clip, path: str | Path) -> Path:
    """Write ``clip`` atomically to ``path``."""
    sk = clip.skeleton
    arrays: dict[str, np.ndarray] = {
        "root": clip.root,
        "rotations": clip.rotations,
        "offsets": sk.offsets,
        "tips": sk.tips,
        "radii": sk.radii,
        "parents": sk.parents,
    }
    if clip.root_motion is not None:
        arrays["rm_translation"] = clip.root_motion.translation
        arrays["rm_heading"] = clip.root_motion.heading
    header = {
        "format": FORMAT,
        "version": VERSION,
        "name": clip.name,
        "fps": clip.fps,
        "loop": clip.loop,
        "markers": clip.markers,
        "joints": list(sk.names),
        "sha256": _digest(arrays),
    }
    buf = io.BytesIO()
    np.savez_compressed(buf, header=np.frombuffer(json.dumps(header).encode(), dtype=np.uint8), **arrays)
    return atomic_write(path, lambda f: f.write(buf.getvalue()))


def load_clip(path: str | Path) -> Clip:
    """Read a clip, checking format, version and checksum; raises :class:`ClipFileError`."""
    path = Path(path)
    raw = path.read_bytes()
    try:
        with np.load(io.BytesIO(raw), allow_pickle=False) as data:
            arrays = {k: data[k] for k in data.files}
    except (zipfile.BadZipFile, OSError, ValueError, EOFError, KeyError) as exc:
        raise ClipFileError(f"{path}: not a readable clip file ({exc})") from exc
    if "header" not in arrays:
        raise ClipFileError(f"{path}: no header; not a {FORMAT} file")
    try:
        header: dict[str, Any] = json.loads(arrays.pop("header").tobytes().decode())
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ClipFileError(f"{path}: header is corrupt ({exc})") from exc
    if header.get("format") != FORMAT:
        raise ClipFileError(f"{path}: format {header.get('format')!r}, expected {FORMAT!r}")
    version = header.get("version")
    if not isinstance(version, int) or version > VERSION or version < 1:
        raise ClipFileError(f"{path}: clip format version {version!r}; this build reads versions 1..{VERSION}")
    if _digest(arrays) != header.get("sha256"):
        raise ClipFileError(f"{path}: checksum mismatch; the file is corrupt")
    try:
        sk = Skeleton(tuple(header["joints"]), arrays["parents"], arrays["offsets"], arrays["tips"], arrays["radii"])
        rm = None
        if "rm_translation" in arrays:
            rm = RootMotion(arrays["rm_translation"], arrays["rm_heading"])
        return Clip(
            name=header["name"],
            skeleton=sk,
            fps=float(header["fps"]),
            root=arrays["root"],
            rotations=arrays["rotations"],
            loop=bool(header["loop"]),
            root_motion=rm,
            markers={str(k): float(v) for k, v in header.get("markers", {}).items()},
        )
    except (KeyError, ValueError, TypeError) as exc:
        raise ClipFileError(f"{path}: inconsistent clip data ({exc})") from exc
