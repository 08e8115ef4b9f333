"""Motion-file formats by name: their suffixes, what reads and writes them — the one table every command asks.

``cycle``, ``cycles``, ``clips add``, ``author edit`` (opening and ``--export``) and the
MoCurves export each kept a suffix list of their own (six of them, already drifting: one
spelled ``.glb, .gltf``, another ``.gltf, .glb``). Here each format is named once with its
suffixes and what it can do, and the commands' lists are queries of this table
(:func:`suffixes`), so a format added here reaches every command that can use it.

Two kinds:

- **clip formats** (``bvh``, ``gltf``, ``ppclip``): a skeleton's motion, read into a
  :class:`~engine.io.motion_file.MotionFile` (``read``) and written from a
  :class:`~engine.clip.Clip` (``write``). BVH and glTF come from other tools (``foreign``):
  their units, up axis and animation are judged or given (``--units``, ``--height``,
  ``--up``, ``--animation``, ``--joint-map``). A ``.ppclip`` is this project's own: metres,
  Y up, root motion kept.
- **trajectory formats** (``csv``, ``npz``, ``rec``): columns over time that ``cycle``
  analyses. Their readers and writers live with the extractor
  (:mod:`authoring.cycles.formats`, keyed by these names): the engine does not import
  authoring.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from engine.clip import Clip
    from engine.io.motion_file import MotionFile

__all__ = ["FORMATS", "MotionFormat", "motion_format", "suffixes"]


@dataclass(frozen=True)
class MotionFormat:
    """One motion-file format.

    Attributes:
        name: the format's name (a key of :data:`FORMATS`).
        suffixes: file suffixes, lower case, the usual one first.
        skeletal: it holds a skeleton's motion (a clip), not bare columns.
        foreign: written by other tools: units, up axis and animation are judged or given.
        root_motion: it keeps a clip's root motion (others get it baked into the root track).
        read: ``read(path, **options) -> MotionFile`` for a clip format (``None`` otherwise).
        write: ``write(clip, path) -> path`` for a clip format (``None`` otherwise).
        reads: a trajectory format ``cycle`` reads (clip formats: ``read`` says it).
        writes: a trajectory format ``cycle`` writes a loop to.
    """

    name: str
    suffixes: tuple[str, ...]
    skeletal: bool
    foreign: bool = False
    root_motion: bool = False
    read: Callable[..., MotionFile] | None = None
    write: Callable[[Clip, Path], Path] | None = None
    reads: bool = True
    writes: bool = True


def _read_foreign(path: Path, **options: Any) -> MotionFile:
    from engine.io.motion_file import load_motion_loop

    return load_motion_loop(path, **options)


def _read_ppclip(path: Path, **options: Any) -> MotionFile:
    from engine.clipfile import load_clip
    from engine.io.motion_file import MotionFile, MotionFileError
    from engine.io.units import Units
    from engine.io.up_axis import UpAxis, figure_height

    given = sorted(k for k, v in options.items() if v is not None and k != "joint_map")  # a map retargets any clip
    if given:
        raise MotionFileError(
            f"{path}: {', '.join('--' + k.replace('_', '-') for k in given)} only apply to a "
            f"file from another tool ({', '.join(suffixes(foreign=True))})"
        )
    clip = load_clip(path)
    return MotionFile(
        clip,
        path,
        Units("m", 1.0, "a .ppclip is in metres"),
        "the .ppclip's rate",
        up=UpAxis("y", "a .ppclip is Y up"),
        height=figure_height(clip),
        seamless=clip.loop,
        file_frames=clip.num_frames,
        file_joints=clip.skeleton.num_joints,
    )


def _write_bvh(clip: Clip, path: Path) -> Path:
    """BVH has no loop flag: a loop is written closed (its first pose again, moved on by its travel), as ``cycle`` writes it."""
    from engine.io.bvh import write_bvh
    from engine.io.bvh_convert import clip_to_bvh
    from engine.io.loop_export import closed

    return write_bvh(path, clip_to_bvh(closed(clip, clip.root_travel()) if clip.loop else clip))


def _write_gltf(clip: Clip, path: Path) -> Path:
    from engine.io.gltf_write import write_gltf

    return write_gltf(path, clip)


def _write_ppclip(clip: Clip, path: Path) -> Path:
    from engine.clipfile import save_clip

    return save_clip(clip, path)


FORMATS: dict[str, MotionFormat] = {
    f.name: f
    for f in (
        MotionFormat("bvh", (".bvh",), skeletal=True, foreign=True, read=_read_foreign, write=_write_bvh),
        MotionFormat("gltf", (".glb", ".gltf"), skeletal=True, foreign=True, read=_read_foreign, write=_write_gltf),
        MotionFormat("ppclip", (".ppclip",), skeletal=True, root_motion=True, read=_read_ppclip, write=_write_ppclip),
        MotionFormat("csv", (".csv",), skeletal=False),
        MotionFormat("npz", (".npz",), skeletal=False),
        MotionFormat("rec", (".rec",), skeletal=False, writes=False),
    )
}
"""Every motion-file format, by name."""


def motion_format(path: str | Path) -> MotionFormat | None:
    """The format of ``path`` by its suffix (any case), or ``None`` for a suffix no format has."""
    suffix = Path(path).suffix.lower()
    return next((f for f in FORMATS.values() if suffix in f.suffixes), None)


def suffixes(
    *,
    skeletal: bool | None = None,
    foreign: bool | None = None,
    readable: bool | None = None,
    writable: bool | None = None,
) -> tuple[str, ...]:
    """The suffixes of the formats matching every condition given (``None``: either way), in table order."""

    def fits(f: MotionFormat) -> bool:
        can_read = f.read is not None if f.skeletal else f.reads
        can_write = f.write is not None if f.skeletal else f.writes
        return all(
            want is None or have == want
            for want, have in (
                (skeletal, f.skeletal),
                (foreign, f.foreign),
                (readable, can_read),
                (writable, can_write),
            )
        )

    return tuple(s for f in FORMATS.values() if fits(f) for s in f.suffixes)
