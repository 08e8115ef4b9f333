"""One door for motion files as people have them: BVH, glTF and GLB to a clip, with what was decided.

Every command that takes a motion file (``cycle``, ``cycles``, ``clips add``, ``author edit``)
calls :func:`load_motion` with the user's options — ``animation`` (glTF: name or index,
default the first), ``units`` (``cm|m|mm|in|cmu``, default judged by the figure), ``up``
(default judged by the figure: a Blender export keeps Z up), whether to skip a T-pose lead-in
— and gets a :class:`MotionFile`: the clip in metres with +Y up plus the decisions (unit, up
axis and why, the figure's height, frame rate and where it came from, warnings such as a
``Frames:`` count that was off), which ``--json`` prints via :meth:`MotionFile.summary`. :func:`load_joint_map`
reads a ``--joint-map`` file and :func:`to_puppet` retargets, saying which map it used.
"""

from __future__ import annotations

import json
import warnings
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from engine.clip import Clip
from engine.errors import FormatError
from engine.io.bvh import BvhError, BvhWarning, read_bvh
from engine.io.formats import motion_format, suffixes
from engine.io.gltf import GltfError, read_gltf
from engine.io.units import Units, given_height, given_units, judge_units
from engine.io.up_axis import UpAxis, figure_height, given_up, judge_up, stood_up
from engine.npz_safe import read_bounded
from engine.skeleton import Skeleton

__all__ = [
    "MOTION_SUFFIXES",
    "MotionFile",
    "MotionFileError",
    "load_motion",
    "load_motion_loop",
    "load_joint_map",
    "to_puppet",
    "scaled_clip",
]

MOTION_SUFFIXES = suffixes(foreign=True)
"""Files from other tools (BVH, glTF, GLB): :data:`engine.io.formats.FORMATS` says which."""
_CONVENTION = UpAxis("y", "the format's convention")
MAX_MAP_FILE = 1 << 20


class MotionFileError(FormatError):
    """A motion file, option or joint map that cannot be used; the message says which and why."""


@dataclass(frozen=True)
class MotionFile:
    """A motion file read as a clip in metres.

    Attributes:
        clip: the motion, on the file's own skeleton.
        source: the file.
        units: the length unit decision (name, metres per unit, basis).
        fps_basis: where the clip's frame rate came from.
        animation: the glTF animation's name (``None`` for BVH).
        animations: every animation name in a glTF file.
        skipped: leading frames dropped (a T-pose lead-in).
        warnings: what was tolerated on the way (e.g. a ``Frames:`` count that was off).
        seamless: the clip is a loop read from a closed file, its closing frame dropped
            (:func:`load_motion_loop`).
        up: the file's up axis and why (the clip is stood up: +Y is up).
        height: the figure's standing height in metres (median over frames).
        file_frames: frames as the file holds them (BVH rows; a glTF animation's most keys).
        file_joints: joints as the file declares them (before a static root is folded away).
    """

    clip: Clip
    source: Path
    units: Units
    fps_basis: str
    animation: str | None = None
    animations: tuple[str, ...] = ()
    skipped: int = 0
    warnings: tuple[str, ...] = ()
    seamless: bool = False
    up: UpAxis = _CONVENTION
    height: float = 0.0
    file_frames: int = 0
    file_joints: int = 0

    @property
    def unit_note(self) -> str | None:
        """What to tell the user when the size was not read off a unit of a human figure (scaled, or judged by extent).

        The caller names the file in front of it."""
        u = self.units
        if u.target is not None:
            return f"{u.basis} (every length times {u.scale:.4g})"
        if u.basis.startswith("no legs"):
            return f"unit {u.name} judged without legs ({u.basis}); --units or --height overrides"
        return None

    def summary(self) -> dict[str, Any]:
        """What ``--json`` reports about the input."""
        out: dict[str, Any] = {
            "units": self.units.name,
            "unit_scale": self.units.scale,
            "units_basis": self.units.basis,
            "up": self.up.name,
            "up_basis": self.up.basis,
            "height": round(self.height, 4),
            "fps": self.clip.fps,
            "fps_basis": self.fps_basis,
            "frames": self.clip.num_frames,
            "joints": self.clip.skeleton.num_joints,
            "file_frames": self.file_frames,
            "file_joints": self.file_joints,
        }
        if self.units.target is not None:
            out["scaled_to"] = self.units.target
        if self.skipped:
            out["skipped_frames"] = self.skipped
        if self.animation is not None:
            out["animation"] = self.animation
        if self.warnings:
            out["warnings"] = list(self.warnings)
        return out


def scaled_clip(clip: Clip, k: float) -> Clip:
    """``clip`` with every length multiplied by ``k`` (offsets, tips, root, translations).

    Radii are left alone: a file without them gets the skeleton's default in metres.
    """
    if k == 1.0:
        return clip
    sk = clip.skeleton
    skeleton = Skeleton(sk.names, sk.parents, sk.offsets * k, sk.tips * k, sk.radii)
    rm = clip.root_motion
    if rm is not None:
        rm = replace(rm, translation=rm.translation * k)
    return replace(
        clip,
        skeleton=skeleton,
        root=clip.root * k,
        root_motion=rm,
        translations=None if clip.translations is None else clip.translations * k,
    )


def _units(
    clip: Clip, units: str | None, metric: bool, joint_map: dict[str, str] | None, height: float | None = None
) -> Units:
    if height is not None:
        if units is not None:
            raise MotionFileError("give --units or --height, not both")
        try:
            return given_height(height, figure_height(clip))
        except ValueError as exc:
            raise MotionFileError(str(exc)) from None
    if units is not None:
        try:
            return given_units(units)
        except ValueError as exc:
            raise MotionFileError(str(exc)) from None
    return judge_units(clip.skeleton, metric=metric, joint_map=joint_map)


def _stood(clip: Clip, up: str | None, joint_map: dict[str, str] | None) -> tuple[Clip, UpAxis]:
    """The clip with its up axis (given, or judged by the figure) turned to +Y."""
    if up is not None:
        try:
            axis = given_up(up)
        except ValueError as exc:
            raise MotionFileError(str(exc)) from None
    else:
        axis = judge_up(clip, joint_map)
    return stood_up(clip, axis), axis


def _finish(
    raw: Clip,
    path: Path,
    units: str | None,
    up: str | None,
    metric: bool,
    joint_map: dict[str, str] | None,
    height: float | None,
    **decided: Any,
) -> MotionFile:
    """The file's clip stood up and in metres, with those decisions (``decided``: the format's own)."""
    standing, axis = _stood(raw, up, joint_map)
    unit = _units(standing, units, metric=metric, joint_map=joint_map, height=height)
    clip = scaled_clip(standing, unit.scale)
    return MotionFile(clip, path, unit, up=axis, height=figure_height(clip), **decided)


def _load_bvh(
    path: Path,
    units: str | None,
    skip_tpose: bool,
    joint_map: dict[str, str] | None,
    up: str | None,
    height: float | None,
) -> MotionFile:
    from engine.io.bvh_convert import detect_tpose_frames

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", BvhWarning)
        motion = read_bvh(path)
    told = tuple(str(w.message) for w in caught if issubclass(w.category, BvhWarning))
    if motion.num_frames == 0:
        raise MotionFileError(f"{path}: the file holds no frames")
    lead = detect_tpose_frames(motion) if skip_tpose else 0
    raw = motion.to_clip(scale=1.0, skip_frames=lead)
    return _finish(
        raw,
        path,
        units,
        up,
        False,
        joint_map,
        height,
        fps_basis="BVH Frame Time",
        skipped=lead,
        warnings=told,
        file_frames=motion.num_frames,
        file_joints=motion.num_joints,
    )


def _load_gltf(
    path: Path,
    units: str | None,
    animation: int | str | None,
    fps: float | None,
    joint_map: dict[str, str] | None,
    up: str | None,
    height: float | None,
) -> MotionFile:
    from engine.io.gltf_clip import animation_rate, find_animation, gltf_clip

    asset = read_gltf(path)
    anim = find_animation(asset, 0 if animation is None else animation)
    index = asset.animations.index(anim)
    raw = gltf_clip(asset, index, fps=fps)
    keys = max((len(c.times) for c in anim.channels), default=0)
    return _finish(
        raw,
        path,
        units,
        up,
        True,
        joint_map,
        height,
        fps_basis=animation_rate(anim, fps)[1],
        animation=anim.name,
        animations=tuple(a.name for a in asset.animations),
        file_frames=keys,
        file_joints=len(asset.skins[0].joints) if asset.skins else raw.skeleton.num_joints,
    )


def load_motion(
    path: str | Path,
    animation: int | str | None = None,
    units: str | None = None,
    skip_tpose: bool = True,
    fps: float | None = None,
    joint_map: dict[str, str] | None = None,
    up: str | None = None,
    height: float | None = None,
) -> MotionFile:
    """Read a ``.bvh``, ``.gltf`` or ``.glb`` motion as a clip in metres, +Y up.

    Args:
        path: the file.
        animation: glTF animation name or index (default the first); refused for BVH.
        units: ``m``, ``cm``, ``mm``, ``in`` or ``cmu``; default judged by the figure.
        skip_tpose: drop a BVH T-pose lead-in (CMU conversions).
        fps: glTF sampling rate (default: from the key spacing).
        joint_map: puppet joint → source joint, when given (helps judge units on odd names).
        up: the file's up axis (``x``, ``y``, ``z``, ``-x``…); default judged by the figure
            (:mod:`engine.io.up_axis`). The clip comes back with that axis turned to +Y.
        height: scale the figure to stand this tall, metres (``--height``; instead of ``units``).

    Raises:
        MotionFileError: unknown type, wrong option, or a file that cannot be read (the
            format's own error, naming file and place, is the message).
        FileNotFoundError: no such file.
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no such file: {path}")
    fmt = motion_format(path)
    if fmt is None or not fmt.foreign:
        raise MotionFileError(
            f"{path}: not a motion file ({path.suffix.lower() or 'no suffix'}); use one of {', '.join(MOTION_SUFFIXES)}"
        )
    try:
        if fmt.name == "bvh":
            if animation is not None:
                raise MotionFileError(f"{path}: --animation is for glTF files; a BVH holds one motion")
            return _load_bvh(path, units, skip_tpose, joint_map, up, height)
        return _load_gltf(path, units, animation, fps, joint_map, up, height)
    except (BvhError, GltfError) as exc:
        raise MotionFileError(str(exc)) from None


def load_motion_loop(
    path: str | Path,
    animation: int | str | None = None,
    units: str | None = None,
    joint_map: dict[str, str] | None = None,
    up: str | None = None,
    height: float | None = None,
) -> MotionFile:
    """:func:`load_motion`, with a file that already is a loop read as one.

    A loop this project wrote (``cycle -o loop.bvh``: its last pose repeats its first) or a
    game asset's single seamless cycle comes back with ``loop`` set and the closing frame
    dropped (see :func:`engine.io.loop_export.opened`); it is judged on every frame, since
    a T-pose lead-in check must not cut a closed loop. Any other file is the take as
    :func:`load_motion` reads it (its T-pose lead-in skipped).
    """
    from engine.io.loop_export import is_seamless, opened

    whole = load_motion(
        path, animation=animation, units=units, joint_map=joint_map, skip_tpose=False, up=up, height=height
    )
    if whole.clip.loop:
        return whole
    if is_seamless(whole.clip):
        return replace(whole, clip=opened(whole.clip), seamless=True)
    if whole.animation is not None:
        return whole
    return load_motion(path, units=units, joint_map=joint_map, up=up, height=height)


def load_joint_map(path: str | Path) -> dict[str, str]:
    """A ``--joint-map`` file: a JSON object of source joint name → puppet joint name.

    Raises :class:`MotionFileError` for anything else (not JSON, not an object of strings,
    unknown puppet joints, one puppet joint given twice, no hips).
    """
    from engine.humanoid import humanoid_skeleton

    path = Path(path)
    try:
        data = json.loads(read_bounded(path, MAX_MAP_FILE).decode("utf-8"))
    except (OSError, ValueError) as exc:  # missing, too big, not UTF-8, not JSON
        raise MotionFileError(f"{path}: not a readable joint map ({type(exc).__name__}: {exc})"[:300]) from None
    except RecursionError:
        raise MotionFileError(f"{path}: not a readable joint map (JSON nested too deeply)") from None
    if (
        not isinstance(data, dict)
        or not data
        or not all(isinstance(k, str) and isinstance(v, str) for k, v in data.items())
    ):
        raise MotionFileError(f"{path}: a joint map is a JSON object of source joint name -> puppet joint name")
    puppet = humanoid_skeleton().names
    unknown = sorted({v for v in data.values() if v not in puppet})
    if unknown:
        raise MotionFileError(f"{path}: unknown puppet joints {unknown}; the puppet has {', '.join(puppet)}")
    out: dict[str, str] = {}
    for src, dst in data.items():
        if dst in out:
            raise MotionFileError(f"{path}: puppet joint {dst!r} is given twice ({out[dst]!r} and {src!r})")
        out[dst] = src
    if puppet[0] not in out:
        raise MotionFileError(f"{path}: the map must give the puppet's root {puppet[0]!r}")
    return out


def to_puppet(clip: Clip, joint_map: dict[str, str] | None = None, map_name: str | None = None) -> tuple[Clip, str]:
    """``clip`` retargeted onto the puppet, and the name of the map used (a family, or ``map_name``)."""
    from engine.humanoid import humanoid_skeleton
    from engine.io.joint_shape import guess_clip_joint_map
    from engine.io.retarget import retarget

    names = clip.skeleton.names
    if joint_map is not None:
        missing = sorted({s for s in joint_map.values() if s not in names})
        if missing:
            raise MotionFileError(f"joint map names source joints the file does not have: {missing[:8]}")
        return retarget(clip, humanoid_skeleton(), joint_map=joint_map, aims={}), map_name or "given"
    try:
        family, mapping, aims = guess_clip_joint_map(clip)
    except ValueError as exc:
        raise MotionFileError(f"{exc}; give one with --joint-map FILE") from None
    return retarget(clip, humanoid_skeleton(), joint_map=mapping, aims=aims), family
