"""Saving and exporting an edited cycle: atomic ``.ppclip`` + session side file, BVH, glTF.

:func:`save_session` writes the edited clip with the engine's own format (versioned,
checksummed, atomic; with the root's fitted curve when the session has one) and, beside it, ``<name>.mocurves.json`` with what a clip cannot hold:
the scale tracks and the pinned keypoints. The side file records the clip's SHA-256 so a
pair that does not belong together is refused instead of silently mismatched; it also keeps
the entry of the clip it replaces (``previous``), because the two files are two atomic writes:
a save killed or out of disk space between them leaves the old clip, which then still opens
with its own session; every value
in it is checked against the clip (shapes, ranges, types), and whatever is wrong with it
is a :class:`SessionFileError`. JSON floats
round-trip exactly (``repr``), so a reload is bit-for-bit.

:func:`export_clip` picks the format from the suffix. BVH and glTF have no root-motion
track, so the travel is baked into the root there (other tools then see the character
walk); ``.ppclip`` keeps it as root motion.
"""

from __future__ import annotations

import hashlib
import json
import tempfile
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from authoring.mocurves.session import EditSession
from authoring.paired_save import entry_for, write_pair
from engine import quat
from engine.clip import Clip
from engine.clipfile import load_clip_curve, save_clip
from engine.errors import FormatError
from engine.io.formats import motion_format, suffixes
from engine.npz_safe import read_bounded

__all__ = [
    "save_session",
    "load_session",
    "side_path",
    "export_clip",
    "bake_root_motion",
    "SessionFileError",
    "EXPORT_SUFFIXES",
]

SIDE_FORMAT = "puppetphone-mocurves"
SIDE_VERSION = 1
MAX_SIDE_FILE = 64 << 20
MAX_SCALE = 100.0
EXPORT_SUFFIXES = suffixes(skeletal=True, writable=True)
"""What ``--export`` writes: every clip format of :data:`engine.io.formats.FORMATS`."""
_UP = np.array([0.0, 1.0, 0.0])


class SessionFileError(FormatError):
    """A session side file that is unreadable, of a newer version, or not of this clip."""


def side_path(path: Path) -> Path:
    """The MoCurves side file that goes with a ``.ppclip``."""
    return path.with_name(path.name.removesuffix(path.suffix) + ".mocurves.json")


def _clip_digest(clip: Clip) -> str:
    h = hashlib.sha256()
    for a in (clip.root, clip.rotations):
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()


def save_session(session: EditSession, path: str | Path) -> Path:
    """Write the shown state atomically: ``path`` (``.ppclip``) and its ``.mocurves.json``.

    The side file's checksum is taken on the clip as :func:`load_session` will see it — the
    clip is written to bytes and read back first — because loading renormalises the rotations,
    which can change their last bit: a checksum of the clip in memory made saved work
    unopenable ("belongs to another version").
    """
    p = Path(path)
    if p.suffix != ".ppclip":
        raise ValueError(f"{p}: a session is saved as .ppclip (use export_clip for BVH/glTF)")
    st = session.state
    with tempfile.TemporaryDirectory() as tmp:
        # The scale tracks ride in the clip's scale channel too; the root curve as the clip's curve section.
        staged = save_clip(session.clip, Path(tmp) / p.name, root_curve=session.root_curve)
        data = staged.read_bytes()
        reloaded, _curve = load_clip_curve(staged)
    side = {
        "format": SIDE_FORMAT,
        "version": SIDE_VERSION,
        "clip_sha256": _clip_digest(reloaded),
        "scales": [[float(x) for x in row] for row in st.scales],
        "pins": {k: sorted(v) for k, v in st.pins.items()},
        "tau": session.tau,
        "sigma": session.sigma,
    }
    # Side file first, carrying the entry of the clip still on disk (authoring.paired_save): a
    # kill or a full disk between the two writes never leaves a pair that is refused or mismatched.
    return write_pair(p, data, side_path(p), side, _entry_on_disk(p))


def _read_side(side_file: Path) -> Any:
    """The decoded side file (``None`` when there is none; raises :class:`SessionFileError` when unreadable)."""
    if not side_file.exists():
        return None
    try:
        return json.loads(read_bounded(side_file, MAX_SIDE_FILE).decode("utf-8"))
    except (OSError, ValueError, RecursionError) as exc:
        raise SessionFileError(f"{side_file}: unreadable session file ({type(exc).__name__}: {exc})"[:300]) from None


def _entry_on_disk(p: Path) -> dict[str, Any] | None:
    """What the clip at ``p`` opens with now: its side file's entry, or "the clip alone" (``None``: no clip)."""
    try:
        clip, _curve = load_clip_curve(p)
    except (OSError, ValueError):
        return None
    digest = _clip_digest(clip)
    try:
        entry = entry_for(_read_side(side_path(p)), digest)
    except SessionFileError:
        entry = None
    return entry or {"format": SIDE_FORMAT, "version": SIDE_VERSION, "clip_sha256": digest, "plain": True}


def load_session(path: str | Path) -> EditSession:
    """An :class:`EditSession` from a ``.ppclip`` (and its side file when there is one)."""
    p = Path(path)
    clip, root_curve = load_clip_curve(p)
    if not clip.loop:
        raise ValueError(f"{p}: clip {clip.name!r} is not a loop; MoCurves edit cycles")
    side_file = side_path(p)
    side = _read_side(side_file)
    if side is None:
        return EditSession(clip, root_curve=root_curve)
    entry = entry_for(side, _clip_digest(clip))
    if entry is not None and entry.get("plain") is True:  # saved over a clip that had no session: it opens alone
        return EditSession(clip, root_curve=root_curve)
    try:
        scales, tau, sigma, pins = _side_values(side if entry is None else entry, clip)
    except SessionFileError as exc:
        raise SessionFileError(f"{side_file}: {exc}") from None
    if entry is None:
        raise SessionFileError(
            f"{side_file}: belongs to another version of {p.name}; move it away to open the clip alone"
        )
    return EditSession(clip, scales, tau=tau, sigma=sigma, pins=pins, root_curve=root_curve)


def _side_values(side: Any, clip: Clip) -> tuple[np.ndarray, int, float, dict[str, list[int]]]:
    """Scales, τ, σ and pins of a decoded side file, every one checked against ``clip``."""
    if not isinstance(side, dict) or side.get("format") != SIDE_FORMAT:
        raise SessionFileError("not a MoCurves session file")
    version = side.get("version")
    if not isinstance(version, int) or isinstance(version, bool) or version < 1:
        raise SessionFileError(f"version {repr(version)[:20]} is not a version number")
    if version > SIDE_VERSION:
        raise SessionFileError(f"version {version} is newer than this build reads ({SIDE_VERSION})")
    frames, joints = clip.num_frames, clip.skeleton.num_joints
    rows = side.get("scales")
    if (
        not isinstance(rows, list)
        or len(rows) != frames
        or not all(isinstance(r, list) and len(r) == joints for r in rows)
        or not all(isinstance(x, (int, float)) and not isinstance(x, bool) for r in rows for x in r)
    ):
        raise SessionFileError(f"scales must be {frames} rows of {joints} numbers")
    scales = np.array(rows, dtype=np.float64)
    if not (np.isfinite(scales).all() and (scales > 0).all() and (scales <= MAX_SCALE).all()):
        raise SessionFileError(f"scales must be in (0, {MAX_SCALE:g}]")
    tau, sigma = side.get("tau", 6), side.get("sigma", 0.08)
    if not isinstance(tau, int) or isinstance(tau, bool) or not 1 <= tau <= frames:
        raise SessionFileError(f"tau must be a whole number of keypoints in 1..{frames}")
    if isinstance(sigma, bool) or not isinstance(sigma, (int, float)) or not 0.0 < sigma <= 10.0:
        raise SessionFileError("sigma must be a number in (0, 10]")
    pins = side.get("pins", {})
    if not isinstance(pins, dict) or not all(
        isinstance(k, str)
        and isinstance(v, list)
        and all(isinstance(i, int) and not isinstance(i, bool) and 0 <= i < frames for i in v)
        for k, v in pins.items()
    ):
        raise SessionFileError(f"pins must map item names to keypoints in 0..{frames - 1}")
    return scales, tau, float(sigma), pins


def bake_root_motion(clip: Clip) -> Clip:
    """``clip`` with its root motion put back into the root track (for formats without it)."""
    rm = clip.root_motion
    if rm is None:
        return clip
    yaw = quat.from_axis_angle(_UP, rm.heading)
    rot = clip.rotations.copy()
    rot[:, 0] = quat.mul(yaw, rot[:, 0])
    return replace(clip, root=quat.rotate(yaw, clip.root) + rm.translation, rotations=rot, root_motion=None)


def export_clip(clip: Clip, path: str | Path) -> Path:
    """Write ``clip`` as ``.ppclip``, ``.bvh`` or ``.glb``/``.gltf`` (by suffix), atomically."""
    p = Path(path)
    fmt = motion_format(p)
    if fmt is None or fmt.write is None:
        raise ValueError(f"{p}: export to one of {', '.join(EXPORT_SUFFIXES)}")
    return fmt.write(clip if fmt.root_motion else bake_root_motion(clip), p)
