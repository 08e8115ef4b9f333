"""A set of clips as plain JSON, for the game set-up a recording carries.

Which clips a game plays is part of its set-up (see ``games/base.py``): ``play --clips
DIR`` reads the library *once*, in the launcher, and the clips themselves travel in
the set-up, so ``Game.install`` stays a function of the set-up alone and a recording
replays with the very clips it was made with — on another machine, after the library
was edited or deleted. (Storing only the content hash would make the recording
unplayable the moment the library changed; the clips cost a few tens of KB of header.)

Layout: ``{"sha256": hash of the canonical JSON of "clips", "clips": {role: {"name", "fps", "loop", "markers",
"frames", "data": base64(zlib(float64 root | rotations | root-motion translation |
heading))}}}``. All clips are on the puppet's skeleton (the library refuses others), so
the skeleton is not repeated; :func:`decode` rebuilds and checks every clip and the set
hash, raising :class:`~engine.cliplib.library.ClipLibraryError` in one line otherwise.
"""

from __future__ import annotations

import base64
import binascii
import hashlib
import json
import math
import zlib
from collections.abc import Mapping
from typing import Any

import numpy as np

from engine.clip import Clip, RootMotion
from engine.cliplib.library import ClipLibraryError
from engine.cliplib.roles import RoleError, normalise_role
from engine.skeleton import Skeleton

__all__ = ["encode", "decode"]

_MAX_FRAMES = 100_000
_MAX_CLIPS = 64
#: All clips of a set together, decoded (float64): a recording's header (16 MB at most) holds
#: far less real motion than this, while 64 clips of 100,000 frames would take gigabytes.
_MAX_DECODED = 64 << 20


def encode(clips: Mapping[str, Clip]) -> dict[str, Any]:
    """The set-up value for ``clips`` by role."""
    out = {}
    for role, clip in sorted(clips.items()):
        parts = [clip.root, clip.rotations]
        if clip.root_motion is not None:
            parts += [clip.root_motion.translation, clip.root_motion.heading[:, None]]
        raw = b"".join(np.ascontiguousarray(p, dtype="<f8").tobytes() for p in parts)
        out[role] = {
            "name": clip.name,
            "fps": clip.fps,
            "loop": clip.loop,
            "markers": dict(clip.markers),
            "frames": clip.num_frames,
            "root_motion": clip.root_motion is not None,
            "data": base64.b64encode(zlib.compress(raw, 9)).decode("ascii"),
        }
    return {"sha256": _payload_digest(out), "clips": out}


def _payload_digest(payload: Any) -> str:
    """SHA-256 of the clips' canonical JSON: what a recording carries, bit for bit."""
    return hashlib.sha256(json.dumps(payload, sort_keys=True).encode()).hexdigest()


def _clip(role: str, e: Any, skeleton: Skeleton) -> Clip:
    if not isinstance(e, dict):
        raise ClipLibraryError(f"recorded clip {role!r} is not an object")
    keys = ("name", "fps", "loop", "frames", "root_motion", "markers")
    name, fps, loop, frames, rm, markers = (e.get(k) for k in keys)
    if not isinstance(name, str) or not isinstance(loop, bool) or not isinstance(rm, bool):
        raise ClipLibraryError(f"recorded clip {role!r}: name, loop or root_motion has the wrong type")
    if isinstance(fps, bool) or not isinstance(fps, (int, float)) or not 0 < fps <= 1000:
        raise ClipLibraryError(f"recorded clip {role!r}: fps {repr(fps)[:20]} is not in (0, 1000]")
    if isinstance(frames, bool) or not isinstance(frames, int) or not 1 <= frames <= _MAX_FRAMES:
        raise ClipLibraryError(f"recorded clip {role!r}: frames {repr(frames)[:20]} is not in 1..{_MAX_FRAMES}")
    if not isinstance(markers, dict) or not all(
        isinstance(k, str) and isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
        for k, v in markers.items()
    ):
        raise ClipLibraryError(f"recorded clip {role!r}: markers must map names to finite times")
    j = skeleton.num_joints
    per_frame = 3 + 4 * j + (4 if rm else 0)
    try:
        packed = base64.b64decode(str(e.get("data")), validate=True)
        raw = zlib.decompressobj().decompress(packed, per_frame * frames * 8 + 1)  # bounded: no zip bomb
    except (binascii.Error, ValueError, zlib.error):
        raise ClipLibraryError(f"recorded clip {role!r}: its data is not base64 zlib") from None
    if len(raw) != per_frame * frames * 8:
        raise ClipLibraryError(f"recorded clip {role!r}: {len(raw)} bytes of data, expected {per_frame * frames * 8}")
    flat = np.frombuffer(raw, dtype="<f8").astype(np.float64)
    root = flat[: 3 * frames].reshape(frames, 3)
    at = 3 * frames
    rot = flat[at : at + 4 * j * frames].reshape(frames, j, 4)
    at += 4 * j * frames
    motion = None
    if rm:
        motion = RootMotion(flat[at : at + 3 * frames].reshape(frames, 3), flat[at + 3 * frames :].copy())
    try:
        return Clip(name, skeleton, float(fps), root, rot, loop=loop, root_motion=motion, markers=dict(markers))
    except ValueError as exc:
        raise ClipLibraryError(f"recorded clip {role!r}: {exc}") from None


def _declared_bytes(e: Any, joints: int) -> int:
    """What a recorded clip claims it decodes to (0 when it claims nothing usable: :func:`_clip` refuses it)."""
    if not isinstance(e, dict):
        return 0
    frames, rm = e.get("frames"), e.get("root_motion") is True
    if isinstance(frames, bool) or not isinstance(frames, int) or not 1 <= frames <= _MAX_FRAMES:
        return 0
    return (3 + 4 * joints + (4 if rm else 0)) * frames * 8


def decode(value: Any, skeleton: Skeleton) -> dict[str, Clip]:
    """The clips by role of an :func:`encode` value, checked against its set hash."""
    if not (isinstance(value, dict) and isinstance(value.get("clips"), dict) and isinstance(value.get("sha256"), str)):
        raise ClipLibraryError("the recorded clips are not {'sha256': …, 'clips': {…}}")
    if len(value["clips"]) > _MAX_CLIPS:
        raise ClipLibraryError(f"the recording names {len(value['clips'])} clips; the limit is {_MAX_CLIPS}")
    if _payload_digest(value["clips"]) != value["sha256"]:
        raise ClipLibraryError("the recorded clips do not match their hash; the recording was altered")
    j = skeleton.num_joints
    total = sum(_declared_bytes(e, j) for e in value["clips"].values())
    if total > _MAX_DECODED:
        raise ClipLibraryError(
            f"the recorded clips would take {total >> 20} MB decoded; the limit is {_MAX_DECODED >> 20} MB"
        )
    clips = {}
    for role, e in value["clips"].items():
        try:
            name = normalise_role(str(role))
        except RoleError as exc:
            raise ClipLibraryError(f"recorded clips: {exc}") from None
        clips[name] = _clip(name, e, skeleton)
    return clips
