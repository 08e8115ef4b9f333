"""An editing session over a keyframed clip: drags through the tangent solver, holds, undo/redo, files.

Files: a session saves the baked clip as an ordinary ``.ppclip`` (what every player
loads) and, beside it, ``<name>.ppkeys``: the keys and Bézier tangents as JSON (floats
written by ``repr``, so they load back bit-for-bit) with the SHA-256 of the ``.ppclip``
it belongs to. Opening the ``.ppclip`` again picks the curves up from the side file when
the digest matches, and refuses a side file that belongs to another version of the clip.
The side file is written first, so a crash between the two writes leaves a mismatch that
is refused loudly, never a silently wrong pairing.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from authoring.keyframe_curves import keys as key_ops
from authoring.keyframe_curves.limits import retime_segment
from authoring.keyframe_curves.posing import KeyPose, pose_key
from authoring.keyframe_curves.solver import CurveEdit, Drag, Hold, TangentSolver, curve_rig
from authoring.paired_save import entry_for, write_pair
from engine.clipfile import MAX_FILE as MAX_CLIP_FILE
from engine.errors import FormatError
from engine.ik import humanoid_rig
from engine.keyframes import BezierCurves, KeyframedClip, keyframe_clip
from engine.npz_safe import read_bounded
from engine.skeleton import Skeleton

__all__ = ["CurveSession", "CurveFileError", "save_curves", "load_curves", "keys_path"]

FORMAT = "puppetphone-keyframes"
VERSION = 1
MAX_SIDE_FILE = 64 * 1024 * 1024
MAX_FPS = 1000.0  # as a clip file's
MAX_FRAMES = 1_000_000  # baked frames (an hour at 240 fps is under)
MAX_VALUE = 1e6  # key times (s), values (m, rad) and tangent handles: far beyond any real clip
REST = "rest"  # the spec of a new clip holding the rest pose
CLOSEST_HALVINGS = 4  # a drag out of reach keeps the farthest reachable point within 1/16 of the way


def standing_root(skeleton: Skeleton) -> np.ndarray:
    """Where the root stands so the rest pose's lowest joint touches the ground."""
    from engine import quat
    from engine.fk import forward_kinematics

    pos, _ = forward_kinematics(skeleton, np.zeros(3), quat.identity(skeleton.num_joints))
    return np.array([0.0, -float(pos[:, 1].min()), 0.0])


class CurveFileError(FormatError):
    """A ``.ppkeys`` side file that cannot be read or does not match its clip."""


def keys_path(clip_path: str | Path) -> Path:
    """The side file of a ``.ppclip``."""
    p = Path(clip_path)
    return p.with_suffix(".ppkeys")


def save_curves(clip: KeyframedClip, path: str | Path) -> Path:
    """Write ``path`` (``.ppclip``, the baked clip) and its ``.ppkeys`` side file, atomically each."""
    from engine.clipfile import save_clip

    p = Path(path)
    if p.suffix.lower() != ".ppclip":
        raise ValueError(f"{p}: a keyframed clip is saved as .ppclip (export glTF/BVH with --export)")
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        staged = save_clip(clip.bake(), Path(tmp) / p.name)
        data = staged.read_bytes()
    c = clip.curves
    side = {"format": FORMAT, "version": VERSION, "clip_sha256": hashlib.sha256(data).hexdigest(),
            "fps": clip.fps, "loop": clip.loop,
            **{k: np.asarray(getattr(c, k)).tolist() for k in ("times", "values", "out_x", "out_y", "in_x", "in_y")}}  # fmt: skip
    write_pair(p, data, keys_path(p), side, _entry_on_disk(p))  # keys first (authoring.paired_save)
    return p


def _entry_on_disk(p: Path) -> dict[str, Any] | None:
    """The keys entry the clip at ``p`` opens with now, if both files are there and agree."""
    try:
        digest = hashlib.sha256(read_bounded(p, MAX_CLIP_FILE)).hexdigest()
        side = json.loads(read_bounded(keys_path(p), MAX_SIDE_FILE).decode("utf-8"))
    except (OSError, ValueError, RecursionError):
        return None
    return entry_for(side, digest)


def load_curves(path: str | Path) -> KeyframedClip:
    """The keyframed clip saved at ``path`` (its ``.ppclip`` and ``.ppkeys``)."""
    from engine.clipfile import load_clip

    p = Path(path)
    clip = load_clip(p)
    side_file = keys_path(p)
    if not side_file.exists():
        raise CurveFileError(f"{p}: no {side_file.name} beside it (open the clip to key it afresh)")
    try:
        side = json.loads(read_bounded(side_file, MAX_SIDE_FILE).decode("utf-8"))
    except (OSError, ValueError, RecursionError) as exc:  # not a regular file, too big, not JSON
        raise CurveFileError(f"{side_file}: unreadable ({type(exc).__name__}: {exc})"[:300]) from None
    if not isinstance(side, dict) or side.get("format") != FORMAT:
        raise CurveFileError(f"{side_file}: not a keyframes file")
    if side.get("version") != VERSION:
        raise CurveFileError(f"{side_file}: version {side.get('version')!r} is not {VERSION}")
    side = entry_for(side, hashlib.sha256(p.read_bytes()).hexdigest())
    if side is None:
        raise CurveFileError(f"{side_file}: belongs to another version of {p.name}")
    fps = side.get("fps")
    if isinstance(fps, bool) or not isinstance(fps, (int, float)) or not 0.0 < fps <= MAX_FPS:
        raise CurveFileError(f"{side_file}: fps {repr(fps)[:30]} is not a number in (0, {MAX_FPS:g}]")
    if not isinstance(side.get("loop"), bool):
        raise CurveFileError(f"{side_file}: loop must be true or false")
    try:
        arrays = [np.asarray(side[k], dtype=np.float64) for k in ("times", "values", "out_x", "out_y", "in_x", "in_y")]
    except (KeyError, TypeError, ValueError) as exc:
        raise CurveFileError(f"{side_file}: {exc}"[:300]) from None
    if not all(np.isfinite(a).all() and (a.size == 0 or np.abs(a).max() <= MAX_VALUE) for a in arrays):
        raise CurveFileError(f"{side_file}: keys hold NaN, infinite or absurd values (beyond {MAX_VALUE:g})")
    span = float(np.ptp(arrays[0])) if arrays[0].size else 0.0
    if span * fps > MAX_FRAMES:  # checked before baking allocates a frame per 1/fps
        raise CurveFileError(f"{side_file}: {span:g} s of keys at {fps:g} fps is over {MAX_FRAMES} frames")
    try:
        curves = BezierCurves(*arrays)
        return KeyframedClip(clip.name, clip.skeleton, curves, float(side["fps"]), bool(side["loop"]),
                             clip.root_motion, dict(clip.markers))  # fmt: skip
    except (KeyError, TypeError, ValueError) as exc:
        raise CurveFileError(f"{side_file}: {exc}"[:300]) from None


@dataclass(frozen=True)
class _State:
    clip: KeyframedClip
    holds: tuple[Hold, ...]
    label: str


class CurveSession:
    """The clip being edited, its holds, and an undo stack of whole states (clips are immutable)."""

    def __init__(self, clip: KeyframedClip, holds: tuple[Hold, ...] = ()) -> None:
        rig = curve_rig(clip, humanoid_rig(clip.skeleton)) if "l_hand" in clip.skeleton.names else curve_rig(clip)
        self.solver = TangentSolver(clip, rig)
        self._undo: list[_State] = [_State(clip, tuple(holds), "open")]
        self._redo: list[_State] = []
        self.preview: KeyframedClip | None = None
        self.revision = 0

    @classmethod
    def from_spec(cls, spec: str, every: int | None = None, duration: float = 1.0) -> CurveSession:
        """A ``.ppclip`` (with its ``.ppkeys``, or keyed afresh), a default clip's name, or ``rest``.

        ``rest`` is a new looping clip of ``duration`` seconds holding the rest pose (two keys:
        the seam); a clip without keys is keyed every ``every`` frames (default 3 for a file,
        which reproduces its frames, and 6 for a default clip).
        """
        from engine.clipfile import load_clip
        from engine.clips import default_clips

        if every is not None and every < 3:
            raise ValueError("keys need at least 3 frames between them (--every 3 or more)")
        p = Path(spec)
        if p.suffix.lower() == ".ppclip":
            return cls(load_curves(p) if keys_path(p).exists() else keyframe_clip(load_clip(p), every=every or 3))
        clips = default_clips()
        if spec == REST:
            skeleton = clips["walk"].skeleton
            if not 0.1 <= duration <= 60.0:
                raise ValueError(f"a new clip lasts 0.1…60 s, not {duration:g}")
            return cls(key_ops.rest_clip(skeleton, "keyposes", duration, 60.0, True, root=standing_root(skeleton)))
        if spec not in clips:
            raise ValueError(f"{spec!r} is neither a .ppclip file nor a default clip ({', '.join(clips)}) nor {REST!r}")
        return cls(keyframe_clip(clips[spec], every=every or 6))

    @property
    def state(self) -> _State:
        return self._undo[-1]

    @property
    def clip(self) -> KeyframedClip:
        """What is shown: a live drag's preview, else the current state."""
        return self.preview if self.preview is not None else self.state.clip

    @property
    def holds(self) -> tuple[Hold, ...]:
        return self.state.holds

    @property
    def history(self) -> list[str]:
        return [s.label for s in self._undo[1:]]

    def _push(self, clip: KeyframedClip, holds: tuple[Hold, ...], label: str) -> None:
        self._undo.append(_State(clip, holds, label))
        self._redo.clear()
        self.solver.clip = clip
        self.revision += 1

    def undo(self) -> bool:
        if len(self._undo) < 2:
            return False
        self._redo.append(self._undo.pop())
        self.solver.clip = self.state.clip
        self.revision += 1
        return True

    def redo(self) -> bool:
        if not self._redo:
            return False
        self._undo.append(self._redo.pop())
        self.solver.clip = self.state.clip
        self.revision += 1
        return True

    def drag(self, joint: str, time: float, *, position: ArrayLike | None = None,
             orientation: ArrayLike | None = None, commit: bool = True) -> CurveEdit:  # fmt: skip
        """One drag from the current state, shown as the preview (and an undo step if ``commit``).

        A target the solver cannot meet keeps the closest solution (§4.4) that holds every pin
        and contact within ε: the solver's nearest such iterate, or the farthest point towards
        the target it does reach (halving the way :data:`CLOSEST_HALVINGS` times), whichever is
        nearer. The result's ``closest_error`` is then the residual to show.
        """
        self.solver.clip = self.state.clip
        res = self.solver.drag(Drag(joint, time, position=position, orientation=orientation), self.holds)
        clip = (
            res.clip if res.reached else self._closest(res, joint, time, None if orientation is not None else position)
        )
        if clip is self.state.clip:
            return res
        if commit:
            self.preview = None
            self._push(clip, self.holds, f"drag {joint}@{time * clip.fps:.0f}")
        else:
            self.preview = clip
            self.revision += 1
        return res

    def _closest(self, res: CurveEdit, joint: str, time: float, position: ArrayLike | None) -> KeyframedClip:
        """The nearest clip to an unreachable ``position`` with the holds kept (``res`` updated with its residual).

        Without a position (a turn) only the solver's nearest feasible iterate is kept."""
        clip = res.closest if res.closest_hold_error <= self.solver.settings.epsilon else self.state.clip
        if position is None:
            return clip
        sk = self.state.clip.skeleton
        j = sk.index(joint)
        goal = np.asarray(position, dtype=np.float64)
        start = self.solver.points(np.array([time]), j, np.zeros(3))[0]
        lo, hi = 0.0, 1.0
        for _ in range(CLOSEST_HALVINGS):
            mid = 0.5 * (lo + hi)
            part = self.solver.drag(Drag(joint, time, position=start + mid * (goal - start)), self.holds)
            if part.reached:
                lo = mid
                miss = float(np.linalg.norm(self.solver.points(np.array([time]), j, np.zeros(3), part.clip)[0] - goal))
                if miss < res.closest_error:
                    clip, res.closest_error, res.closest_hold_error = part.clip, miss, part.hold_error
            else:
                hi = mid
        return clip

    # -- keys (the key-pose workflow, §4.3.1) -----------------------------------------------
    def key_frames(self) -> list[int]:
        """The frame of each key of the shown clip."""
        return [int(f) for f in key_ops.key_frames(self.clip)]

    def add_key(self, frame: int) -> None:
        """A key at ``frame`` (the motion does not change); one undo step."""
        c = self.state.clip
        self._push(key_ops.insert_key(c, c.curves.times[0] + frame / c.fps), self.holds, f"add key {frame}")

    def delete_key(self, k: int) -> None:
        """Remove key ``k``; one undo step."""
        frame = self.key_frames()[k]
        self._push(key_ops.delete_key(self.state.clip, k), self.holds, f"delete key {frame}")

    def move_key(self, k: int, frame: int, commit: bool = True) -> None:
        """Slide key ``k`` to ``frame`` (the preview while dragging; an undo step with ``commit``)."""
        c = self.state.clip
        moved = key_ops.move_key(c, k, c.curves.times[0] + frame / c.fps)
        if commit:
            self.preview = None
            self._push(moved, self.holds, f"move key {k} to {frame}")
        else:
            self.preview = moved
            self.revision += 1

    def pinned_at(self, frame: int) -> tuple[str, ...]:
        """Joints held (pin or contact) at ``frame``: the static IK's pins when posing a key there."""
        n = self.state.clip.num_frames
        return tuple(str(h.joint) for h in self.holds if h.first <= frame % max(n, 1) <= h.last)

    def pose(self, k: int, joint: str, target: ArrayLike | None, commit: bool = True,
             orientation: ArrayLike | None = None) -> KeyPose:  # fmt: skip
        """Drag ``joint`` of key ``k`` towards ``target`` (and/or turn it) with the static IK, closest pose kept."""
        res = pose_key(self.state.clip, k, joint, target, self.pinned_at(self.key_frames()[k]), orientation)
        if commit:
            self.preview = None
            self._push(res.clip, self.holds, f"pose {joint}@key {k}")
        else:
            self.preview = res.clip
            self.revision += 1
        return res

    def set_key(self, k: int, channels: ArrayLike) -> None:
        """Key ``k`` takes a whole pose (channels, e.g. copied from a reference); one undo step."""
        self._push(key_ops.set_key_channels(self.state.clip, k, channels), self.holds, f"set key {k}")

    def cancel_preview(self) -> None:
        """Drop a live gesture's preview."""
        if self.preview is not None:
            self.preview = None
            self.revision += 1

    def commit_preview(self, label: str) -> None:
        """Make a live drag's last preview one undo step."""
        if self.preview is not None:
            clip, self.preview = self.preview, None
            self._push(clip, self.holds, label)

    def retime(self, time: float, sigma: float, commit: bool = True) -> None:
        """Eq. 4.12 at ``time`` by ``σ`` seconds of tangent length (the preview, or one undo step)."""
        c = self.state.clip
        clip = replace(c, curves=retime_segment(c.curves, time, sigma))
        if commit:
            self.preview = None
            self._push(clip, self.holds, f"retime {sigma:+.3f}")
        else:
            self.preview = clip
            self.revision += 1

    def toggle_hold(self, joint: str, first: int, last: int, contact: bool = False) -> None:
        """Add a pin/contact on ``joint`` over frames, or remove the one it has (one undo step)."""
        kept = tuple(h for h in self.holds if h.joint != joint)
        if len(kept) == len(self.holds):
            kept = (*kept, Hold(joint, first, last, contact=contact))
            label = f"{'contact' if contact else 'pin'} {joint} {first}-{last}"
        else:
            label = f"unpin {joint}"
        self._push(self.state.clip, kept, label)
