"""The clip file format (``.ppclip``): versioned, checksummed, written atomically.

A ``.ppclip`` is a zip (numpy ``.npz``) holding a JSON header and the arrays. The
header names the format and its version, the skeleton (names, parents, offsets,
tips, radii), fps, loop flag, markers, and a SHA-256 of the array bytes, so a
file that was truncated or altered is refused with a clear message rather than
loaded as garbage. Readers refuse versions newer than they know, and check every
value before building the clip (sizes before allocation through
:mod:`engine.npz_safe`, then types, finiteness, fps, radii, unit rotations): whatever
is wrong with a file, :func:`load_clip` raises :class:`ClipFileError` and nothing else.

Version 2 adds the optional channels ``translations [F,J,3]`` and ``scales [F,J]``, stored
only when a clip has them; version 1 files (which never do) still read. The container is
open: arrays a reader does not know are covered by the checksum and otherwise ignored, so
other tools may store named extras beside the clip without a new version.

One such extra is read here: the fitted curve of the root position (:class:`~engine.root_curve.RootCurve`,
arrays ``root_curve_control [K,3]`` and ``root_curve_travel [3]``) that ``cycle`` writes so
MoCurves opens the extracted control points. :func:`load_clip` ignores it; :func:`load_clip_curve`
checks it at this same boundary (both arrays or neither, ``4 ≤ K ≤ frames``, finite, bounded).
"""

from __future__ import annotations

import hashlib
import io
import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from engine.atomic import atomic_write_bytes
from engine.clip import Clip, RootMotion
from engine.errors import FormatError
from engine.npz_safe import read_bounded, read_npz
from engine.root_curve import RootCurve
from engine.skeleton import Skeleton

__all__ = ["save_clip", "load_clip", "load_clip_curve", "ClipFileError", "FORMAT", "VERSION"]

FORMAT = "puppetphone-clip"
VERSION = 2
# Limits a real clip is far inside: an hour of 120 fps mocap on a 100-joint skeleton is ~170 MB.
MAX_FILE = 256 << 20
MAX_HEADER = 1 << 20
MAX_JOINTS = 1024
MAX_FPS = 1000.0
MAX_COORDINATE = 1e6  # metres (and radians of heading)


class ClipFileError(FormatError):
    """A clip file that cannot be read: corrupt, truncated, not a clip, or a newer version."""


def _digest(arrays: dict[str, np.ndarray]) -> str:
    h = hashlib.sha256()
    for key in sorted(arrays):
        a = np.ascontiguousarray(arrays[key])
        h.update(key.encode() + a.dtype.str.encode() + str(a.shape).encode() + a.tobytes())
    return h.hexdigest()


def save_clip(clip: Clip, path: str | Path, root_curve: RootCurve | None = None) -> Path:
    """Write ``clip`` atomically to ``path``, with the fitted ``root_curve`` of its root when given."""
    sk = clip.skeleton
    arrays: dict[str, np.ndarray] = {
        "root": clip.root,
        "rotations": clip.rotations,
        "offsets": sk.offsets,
        "tips": sk.tips,
        "radii": sk.radii,
        "parents": sk.parents,
    }
    if clip.translations is not None:
        arrays["translations"] = clip.translations
    if clip.scales is not None:
        arrays["scales"] = clip.scales
    if clip.root_motion is not None:
        arrays["rm_translation"] = clip.root_motion.translation
        arrays["rm_heading"] = clip.root_motion.heading
    if root_curve is not None:
        if not 4 <= root_curve.count <= clip.num_frames:
            raise ValueError(f"a root curve of {root_curve.count} control points does not fit {clip.num_frames} frames")
        arrays["root_curve_control"] = root_curve.control
        arrays["root_curve_travel"] = root_curve.travel
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
    np.savez_compressed(buf, header=np.frombuffer(json.dumps(header).encode(), dtype=np.uint8), **arrays)  # type: ignore[arg-type]  # numpy's stub types **kwds as the allow_pickle flag
    return atomic_write_bytes(path, buf.getvalue())


def _finite(name: str, a: np.ndarray, shape_tail: tuple[int, ...] = ()) -> np.ndarray:
    if a.dtype.kind not in "fiu":
        raise ClipFileError(f"{name} is not numeric ({a.dtype})")
    if shape_tail and a.shape[1:] != shape_tail:
        raise ClipFileError(f"{name} has shape {a.shape}, expected [..., {', '.join(map(str, shape_tail))}]")
    with np.errstate(invalid="ignore"):  # a float32 signalling NaN warns as it widens; refused just below
        a = a.astype(np.float64)
    if not np.isfinite(a).all() or (a.size and float(np.abs(a).max()) > MAX_COORDINATE):
        raise ClipFileError(f"{name} holds NaN, infinite or absurd values (beyond {MAX_COORDINATE:g})")
    return a


def _header(arrays: dict[str, np.ndarray]) -> dict[str, Any]:
    raw = arrays.pop("header")
    if raw.dtype != np.uint8 or raw.ndim != 1 or raw.size > MAX_HEADER:
        raise ClipFileError(f"header is not {MAX_HEADER} bytes or fewer of JSON")
    try:
        header = json.loads(raw.tobytes().decode())
    except (UnicodeDecodeError, json.JSONDecodeError, RecursionError) as exc:
        raise ClipFileError(f"header is corrupt ({type(exc).__name__})") from None
    if not isinstance(header, dict):
        raise ClipFileError("header is not a JSON object")
    return header


def _check_header(header: dict[str, Any]) -> None:
    if header.get("format") != FORMAT:
        raise ClipFileError(f"format {repr(header.get('format'))[:40]}, expected {FORMAT!r}")
    version = header.get("version")
    if not isinstance(version, int) or isinstance(version, bool) or version > VERSION or version < 1:
        raise ClipFileError(f"clip format version {repr(version)[:20]}; this build reads versions 1..{VERSION}")
    fps = header.get("fps")
    if isinstance(fps, bool) or not isinstance(fps, (int, float)) or not 0.0 < fps <= MAX_FPS:
        raise ClipFileError(f"fps {repr(fps)[:20]} is not a number in (0, {MAX_FPS:g}]")
    if not isinstance(header.get("name"), str) or not isinstance(header.get("loop"), bool):
        raise ClipFileError("name must be a string and loop a boolean")
    joints = header.get("joints")
    if not isinstance(joints, list) or not 0 < len(joints) <= MAX_JOINTS or not all(isinstance(j, str) for j in joints):
        raise ClipFileError(f"joints must be a list of 1..{MAX_JOINTS} names")
    markers = header.get("markers", {})
    if not isinstance(markers, dict) or not all(
        isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in markers.values()
    ):
        raise ClipFileError("markers must map names to finite times")


def _root_curve(arrays: dict[str, np.ndarray], frames: int) -> RootCurve | None:
    """The stored root curve, checked: both arrays or neither, ``[K,3]`` with ``4 ≤ K ≤ frames``, ``[3]``."""
    present = [k in arrays for k in ("root_curve_control", "root_curve_travel")]
    if not any(present):
        return None
    if not all(present):
        raise ClipFileError("root curve is incomplete (needs root_curve_control and root_curve_travel)")
    control = _finite("root_curve_control", arrays["root_curve_control"], (3,))
    travel = _finite("root_curve_travel", arrays["root_curve_travel"])
    if control.ndim != 2 or not 4 <= control.shape[0] <= frames or travel.shape != (3,):
        raise ClipFileError(
            f"root curve has shapes {control.shape} and {travel.shape}, expected [4..{frames},3] and [3]"
        )
    return RootCurve(control, travel)


def load_clip(path: str | Path) -> Clip:
    """Read a clip, checking format, version, checksum and every value (see :func:`load_clip_curve`)."""
    return load_clip_curve(path)[0]


def load_clip_curve(path: str | Path) -> tuple[Clip, RootCurve | None]:
    """Read a clip and its root curve (None when the file has none), checking every value.

    Raises:
        ClipFileError: the file is not a readable clip: too big, damaged, of a newer version,
            or with values no clip has (NaN or absurd coordinates, fps not in (0, 1000],
            negative radii, rotations that are not unit quaternions, inconsistent shapes).
        OSError: the file cannot be opened.
    """
    path = Path(path)
    try:
        arrays = read_npz(read_bounded(path, MAX_FILE))
    except ValueError as exc:  # NpzError, or not a regular file / too big
        raise ClipFileError(f"{path}: not a readable clip file ({exc})") from None
    if "header" not in arrays:
        raise ClipFileError(f"{path}: no header; not a {FORMAT} file")
    try:
        header = _header(arrays)
        _check_header(header)
        if _digest(arrays) != header.get("sha256"):
            raise ClipFileError("checksum mismatch; the file is corrupt")
        rotations = _finite("rotations", arrays["rotations"])
        if rotations.ndim != 3 or rotations.shape[-1] != 4:
            raise ClipFileError(f"rotations have shape {rotations.shape}, expected [F,J,4]")
        if rotations.size and float(np.abs(np.linalg.norm(rotations, axis=-1) - 1.0).max()) > 1e-3:
            raise ClipFileError("rotations are not unit quaternions")
        radii = _finite("radii", arrays["radii"])
        if (radii < 0).any():
            raise ClipFileError("radii must not be negative")
        parents = arrays["parents"]
        if parents.dtype.kind not in "iu":
            raise ClipFileError("parents are not integers")
        sk = Skeleton(
            tuple(header["joints"]),
            parents.astype(np.int64),
            _finite("offsets", arrays["offsets"]),
            _finite("tips", arrays["tips"]),
            radii,
        )
        root = _finite("root", arrays["root"], (3,))
        rm = None
        if "rm_translation" in arrays:
            rm = RootMotion(
                _finite("rm_translation", arrays["rm_translation"], (3,)), _finite("rm_heading", arrays["rm_heading"])
            )
            if rm.translation.shape != root.shape or rm.heading.shape != root.shape[:1]:
                raise ClipFileError("root motion does not have one entry per frame")
        channels = {}
        for key, tail in (("translations", (sk.num_joints, 3)), ("scales", (sk.num_joints,))):
            if key in arrays:
                value = _finite(key, arrays[key], tail)
                if value.shape[0] != root.shape[0]:
                    raise ClipFileError(f"{key} do not have one entry per frame")
                channels[key] = value
        if "scales" in channels and (channels["scales"] <= 0).any():
            raise ClipFileError("scales must be positive")
        clip = Clip(
            name=header["name"],
            skeleton=sk,
            fps=float(header["fps"]),
            root=root,
            rotations=rotations,
            loop=header["loop"],
            root_motion=rm,
            markers={str(k): float(v) for k, v in header.get("markers", {}).items()},
            **channels,
        )
        return clip, _root_curve(arrays, clip.num_frames)
    except ClipFileError as exc:
        raise ClipFileError(f"{path}: {exc}") from None
    except (KeyError, ValueError, TypeError) as exc:
        raise ClipFileError(f"{path}: inconsistent clip data ({type(exc).__name__}: {exc})"[:300]) from None
