"""Reading performances and writing loops: BVH, CSV, ``.npz``, input recordings, ``.ppclip``.

A :class:`Performance` is a :class:`Trajectory` plus what is needed to write the loop
back in kind: the column names, and for skeletal input (BVH) the source clip, whose
skeleton the output clip or BVH reuses.

* **BVH, glTF, GLB** — read with :func:`engine.io.motion_file.load_motion` (the leading
  T-pose of CMU conversions skipped, units judged or given, a glTF animation chosen by
  name or index) as a clip; items are the root position (allowed to travel) and every
  joint's rotation as a quaternion (never raw Euler angles, which wrap). ``items``
  selects joints by name.
* **CSV** — a header row, first column ``time`` in seconds, one column per dimension.
  Columns named ``NAME.qw NAME.qx NAME.qy NAME.qz`` form a rotation item, ``NAME.x NAME.y
  NAME.z`` a position item; everything else is a scalar.
* **npz** — ``values [T,N]`` with ``times [T]`` or ``fps``; optional ``names [N]``.
* **recordings** (``.rec``, :mod:`input.recording`) — one controller's samples: its
  position (the stick pivot) and orientation over the fixed-step clock.
"""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from authoring.cycles.extract import CycleResult
from authoring.cycles.heading import normalise, restore
from authoring.cycles.trajectory import Item, Trajectory, TrajectoryError
from engine.atomic import atomic_write_bytes
from engine.clip import Clip
from engine.io.formats import motion_format, suffixes
from engine.io.loop_export import is_seamless
from engine.io.motion_file import MotionFile, MotionFileError, load_motion
from engine.npz_safe import MAX_NPZ_BYTES, read_bounded, read_npz
from engine.root_curve import RootCurve

__all__ = [
    "INPUT_SUFFIXES",
    "OUTPUT_SUFFIXES",
    "Performance",
    "load_performance",
    "loop_clip",
    "save_loop",
    "performance_from_motion",
    "seamless_repeats",
    "is_seamless",
]

INPUT_SUFFIXES = suffixes(foreign=True, readable=True) + suffixes(skeletal=False, readable=True)
"""What ``cycle`` and ``cycles`` read: files from other tools and every trajectory format."""
OUTPUT_SUFFIXES = suffixes(writable=True)
"""What ``cycle`` writes a loop to: every writable format of :data:`engine.io.formats.FORMATS`."""
#: Fewer frames than this hold no two cycles of any period the extractor looks for.
MIN_FRAMES = 4


@dataclass(frozen=True)
class Performance:
    """A performance read from a file.

    Attributes:
        trajectory: what the extractor analyses.
        names: ``[N]`` column names.
        source: the file it came from.
        clip: for skeletal input, the (T-pose-free) clip the columns came from.
        joints: for skeletal input, the joint index of each rotation item, in item order.
        skipped: leading frames dropped (a T-pose lead-in).
        motion: for skeletal input, the file's decisions (units, fps, animation, warnings).
        translated: for skeletal input, the joints whose translation channel moves; each is a
            position item after the rotation items, in this order.
        heading: for skeletal input, the column of the travelling heading item: the root
            position and rotation items are heading-normalised (:mod:`authoring.cycles.heading`).
        performed: cycles the file holds when it is one seamless cycle repeated to be measured
            (:func:`seamless_repeats`): 1; ``None`` for a performance of its own cycles.
    """

    trajectory: Trajectory
    names: tuple[str, ...]
    source: Path
    clip: Clip | None = None
    joints: tuple[int, ...] = ()
    skipped: int = 0
    motion: MotionFile | None = None
    translated: tuple[int, ...] = ()
    heading: int | None = None
    performed: int | None = None


def _select(available: list[str], wanted: list[str] | None, what: str) -> list[str]:
    if not wanted:
        return available
    missing = [w for w in wanted if w not in available]
    if missing:
        raise TrajectoryError(f"no {what} {', '.join(map(repr, missing))}; available: {', '.join(available[:40])}")
    return [a for a in available if a in wanted]


SEAMLESS_REPEATS = 3


def seamless_repeats(clip: Clip) -> Clip:
    """A glTF animation that is one seamless cycle (its last pose is its first), repeated.

    Game assets (Fox's Walk and Run, CesiumMan's walk) hold exactly one cycle, so there is
    nothing to compare a cycle with; repeated :data:`SEAMLESS_REPEATS` times (the root moving
    on by the cycle's travel) they are a performance the extractor can measure like any other.
    Other clips are returned unchanged.
    """
    if not is_seamless(clip):
        return clip
    rot = clip.rotations
    travel = clip.root[-1] - clip.root[0]
    body = slice(0, clip.num_frames - 1)
    reps = SEAMLESS_REPEATS
    root = np.concatenate([clip.root[body] + k * travel for k in range(reps)] + [clip.root[-1:] + (reps - 1) * travel])
    rots = np.concatenate([rot[body]] * reps + [rot[-1:]])
    tr = clip.translations
    tr = None if tr is None else np.concatenate([tr[body]] * reps + [tr[-1:]])
    return Clip(clip.name, clip.skeleton, clip.fps, root, rots, translations=tr)


def _load_skeletal(path: Path, items: list[str] | None, options: dict[str, object]) -> Performance:
    try:
        motion = load_motion(path, **options)  # type: ignore[arg-type]  # the options are load_motion's own names
    except MotionFileError as exc:
        raise TrajectoryError(str(exc)) from None
    return performance_from_motion(motion, items)


def performance_from_motion(motion: MotionFile, items: list[str] | None = None) -> Performance:
    """The performance of a motion file read by :func:`~engine.io.motion_file.load_motion`."""
    path = motion.source
    clip = motion.clip
    if motion.animation is not None:
        clip = seamless_repeats(clip)
    performed = 1 if clip is not motion.clip else None
    sk = clip.skeleton
    chosen = _select(list(sk.names), items, "joint")
    local, level, heading = normalise(clip.root, clip.rotations[:, 0])
    rotations = clip.rotations.copy()
    rotations[:, 0] = level
    cols = [local]
    names = [f"{sk.names[0]}.x", f"{sk.names[0]}.y", f"{sk.names[0]}.z"]
    its = [Item(f"{sk.names[0]}.position", "position", 0, 3, travel=True)]
    joints: list[int] = []
    for name in chosen:
        j = sk.index(name)
        start = 3 + 4 * len(joints)
        cols.append(rotations[:, j])
        names += [f"{name}.qw", f"{name}.qx", f"{name}.qy", f"{name}.qz"]
        its.append(Item(f"{name}.rotation", "rotation", start, start + 4))
        joints.append(j)
    translated: list[int] = []
    if clip.translations is not None:
        # Joints whose bones stretch or slide loop too: their local translation is a position item.
        moving = np.ptp(clip.translations, axis=0).max(axis=1) > 1e-9
        for j in (int(k) for k in np.flatnonzero(moving[1:]) + 1):
            start = 3 + 4 * len(joints) + 3 * len(translated)
            cols.append(clip.translations[:, j])
            names += [f"{sk.names[j]}.tx", f"{sk.names[j]}.ty", f"{sk.names[j]}.tz"]
            its.append(Item(f"{sk.names[j]}.translation", "position", start, start + 3))
            translated.append(j)
    column = 3 + 4 * len(joints) + 3 * len(translated)
    cols.append(heading[:, None])
    names.append(f"{sk.names[0]}.heading")
    its.append(Item(f"{sk.names[0]}.heading", "position", column, column + 1, travel=True))
    traj = Trajectory.uniform(np.concatenate(cols, axis=1), clip.fps, its)
    return Performance(
        traj, tuple(names), path, clip, tuple(joints), motion.skipped, motion, tuple(translated), column, performed
    )


def _items_from_names(names: list[str]) -> list[Item]:
    """Group ``X.qw..X.qz`` into rotations and ``X.x..X.z`` into positions; the rest are scalars."""
    out: list[Item] = []
    c = 0
    while c < len(names):
        stem, _, suffix = names[c].rpartition(".")
        if stem and suffix == "qw" and names[c : c + 4] == [f"{stem}.q{a}" for a in "wxyz"]:
            out.append(Item(stem, "rotation", c, c + 4))
            c += 4
            continue
        if stem and suffix == "x" and names[c : c + 3] == [f"{stem}.{a}" for a in "xyz"]:
            out.append(Item(stem, "position", c, c + 3))
            c += 3
            continue
        out.append(Item(names[c], "scalar", c, c + 1))
        c += 1
    return out


def _load_csv(path: Path, items: list[str] | None) -> Performance:
    try:
        text = read_bounded(path, MAX_NPZ_BYTES).decode("utf-8")
        rows = list(csv.reader(io.StringIO(text)))
    except (ValueError, csv.Error) as exc:  # not UTF-8 text, NUL bytes, not a regular file, too big
        raise TrajectoryError(f"{path}: not a readable CSV file ({type(exc).__name__}: {exc})"[:300]) from None
    rows = [r for r in rows if r and any(x.strip() for x in r)]
    if len(rows) < 2:
        raise TrajectoryError(f"{path}: a CSV performance needs a header row and data rows")
    header = [h.strip() for h in rows[0]]
    if header[0].lower() != "time":
        raise TrajectoryError(f"{path}: the first column must be 'time' (seconds), found {header[0]!r}")
    try:
        data = np.array([[float(x) for x in r] for r in rows[1:]], dtype=np.float64)
    except ValueError as exc:
        raise TrajectoryError(f"{path}: non-numeric value ({exc})") from None
    if data.ndim != 2 or data.shape[1] != len(header):
        raise TrajectoryError(f"{path}: every row needs {len(header)} values")
    return _from_columns(path, data[:, 0], data[:, 1:], header[1:], items)


def _from_columns(
    path: Path, times: NDArray[np.float64], values: NDArray[np.float64], names: list[str], items: list[str] | None
) -> Performance:
    its = _items_from_names(names)
    chosen = _select([it.name for it in its], items, "item")
    keep = [it for it in its if it.name in chosen]
    cols = np.concatenate([np.arange(it.start, it.stop) for it in keep])
    new_items, start = [], 0
    for it in keep:
        width = it.stop - it.start
        new_items.append(Item(it.name, it.kind, start, start + width, it.travel))
        start += width
    traj = Trajectory(times, values[:, cols], tuple(new_items))
    return Performance(traj, tuple(names[c] for c in cols), path)


def _numeric(path: Path, name: str, a: np.ndarray) -> NDArray[np.float64]:
    if a.dtype.kind not in "fiub":
        raise TrajectoryError(f"{path}: {name!r} is not numeric ({a.dtype})")
    with np.errstate(invalid="ignore"):  # a float32 signalling NaN warns as it widens; Trajectory refuses NaN
        return np.asarray(a, dtype=np.float64)


def _load_npz(path: Path, items: list[str] | None) -> Performance:
    try:
        z = read_npz(read_bounded(path, MAX_NPZ_BYTES))
    except ValueError as exc:  # NpzError, or not a regular file / too big
        raise TrajectoryError(f"{path}: {exc}") from None
    if "values" not in z:
        raise TrajectoryError(f"{path}: an .npz performance needs a 'values' array [T,N] (has {sorted(z)})")
    values = _numeric(path, "values", z["values"])
    if values.ndim == 1:
        values = values[:, None]
    if values.ndim != 2:
        raise TrajectoryError(f"{path}: 'values' must be [T,N], not of shape {values.shape}")
    if "times" in z:
        times = _numeric(path, "times", z["times"]).reshape(-1)
    elif "fps" in z:
        fps = _numeric(path, "fps", z["fps"])
        if fps.size != 1 or not 0.0 < float(fps.reshape(-1)[0]) <= 10_000.0:
            raise TrajectoryError(f"{path}: 'fps' must be one number in (0, 10000]")
        times = np.arange(len(values)) / float(fps.reshape(-1)[0])
    else:
        raise TrajectoryError(f"{path}: give 'times' [T] or 'fps' beside 'values'")
    names_arr = z.get("names")
    if names_arr is not None and (names_arr.dtype.kind not in "US" or names_arr.ndim != 1):
        raise TrajectoryError(f"{path}: 'names' must be a list of strings")
    names = [str(n) for n in names_arr] if names_arr is not None else [f"c{c}" for c in range(values.shape[1])]
    if len(names) != values.shape[1]:
        raise TrajectoryError(f"{path}: {len(names)} names for {values.shape[1]} columns")
    return _from_columns(path, times, values, names, items)


def _load_recording(path: Path, items: list[str] | None) -> Performance:
    from input.recording import read_recording

    rec = read_recording(path)
    sources: list[str] = []
    for fr in rec.frames:
        for s in fr.sources():
            if s not in sources:
                sources.append(s)
    chosen = _select(sources, items, "source")
    if not chosen:
        raise TrajectoryError(f"{path}: the recording holds no controller samples")
    src = chosen[0]
    t, pos, ori = [], [], []
    for fr in rec.frames:
        sample = fr.latest(src)
        if sample is None:
            continue
        t.append(fr.frame * rec.header.dt)
        ori.append(sample.orientation)
        pos.append(sample.position if sample.position is not None else np.full(3, np.nan))
    if len(t) < 3:
        raise TrajectoryError(f"{path}: source {src!r} has only {len(t)} samples")
    p = np.asarray(pos)
    cols, names, its = [], [], []
    if np.isfinite(p).all() and np.ptp(p, axis=0).max() > 0:
        cols.append(p)
        names += [f"{src}.x", f"{src}.y", f"{src}.z"]
        its.append(Item(f"{src}.position", "position", 0, 3))
    start = 3 * len(cols)
    cols.append(np.asarray(ori))
    names += [f"{src}.q{a}" for a in "wxyz"]
    its.append(Item(f"{src}.orientation", "rotation", start, start + 4))
    traj = Trajectory(np.asarray(t), np.concatenate(cols, axis=1), tuple(its))
    return Performance(traj, tuple(names), path)


def load_performance(path: str | Path, items: list[str] | None = None, **motion_options: object) -> Performance:
    """Read a performance; ``items`` restricts it to named joints / items / sources.

    ``motion_options`` go to :func:`~engine.io.motion_file.load_motion` for skeletal input
    (``animation``, ``units``, ``joint_map``); other input refuses them.

    Raises:
        TrajectoryError: unreadable or unsuitable content (the message says what).
        FileNotFoundError: no such file.
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no such file: {path}")
    fmt = motion_format(path)
    loaders = {"csv": _load_csv, "npz": _load_npz, "rec": _load_recording}  # the trajectory formats, by name
    if fmt is not None and fmt.foreign:
        perf = _load_skeletal(path, items, {k: v for k, v in motion_options.items() if v is not None})
    elif fmt is None or fmt.name not in loaders:
        raise TrajectoryError(
            f"{path}: unknown input type {path.suffix.lower()!r}; use one of {', '.join(INPUT_SUFFIXES)}"
        )
    else:
        given = sorted(k for k, v in motion_options.items() if v is not None)
        if given:
            raise TrajectoryError(
                f"{path}: {', '.join('--' + k.replace('_', '-') for k in given)} only apply to BVH/glTF input"
            )
        perf = loaders[fmt.name](path, items)
    frames = len(perf.trajectory.times)
    if frames < MIN_FRAMES:  # the feature and period analyses difference neighbouring frames
        raise TrajectoryError(f"{path}: {frames} frame(s); a loop is extracted from at least {MIN_FRAMES}")
    return perf


def loop_clip(result: CycleResult, perf: Performance, name: str | None = None) -> Clip:
    """The loop as a looping clip on the performance's skeleton (skeletal input only)."""
    if perf.clip is None:
        raise TrajectoryError("only skeletal input (BVH) can become a clip or BVH; write .csv or .npz instead")
    src = perf.clip
    s = len(result.loop)
    rots = np.broadcast_to(src.rotations.mean(axis=0), (s, *src.rotations.shape[1:])).copy()
    # Joints that were not analysed keep their mean pose from the performance.
    rots = rots / np.linalg.norm(rots, axis=-1, keepdims=True)
    for k, j in enumerate(perf.joints):
        rots[:, j] = result.loop[:, 3 + 4 * k : 7 + 4 * k]
    root, rots[:, 0], _ = _world_root(result, perf, rots[:, 0])
    translations = None
    if src.translations is not None:
        translations = np.broadcast_to(src.translations.mean(axis=0), (s, *src.translations.shape[1:])).copy()
        first = 3 + 4 * len(perf.joints)
        for k, j in enumerate(perf.translated):
            translations[:, j] = result.loop[:, first + 3 * k : first + 3 * k + 3]
    return Clip(
        name or f"{src.name}_cycle", src.skeleton, s / result.period, root, rots, loop=True, translations=translations
    )


def _world_root(
    result: CycleResult, perf: Performance, level: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """The loop's world root position, root rotation and per-cycle travel (heading restored)."""
    if perf.heading is None:
        return result.loop[:, 0:3], level, result.travel[:3]
    hc = perf.heading
    if 0 not in perf.joints:  # the root rotation was not analysed: it keeps its level mean
        level = np.broadcast_to(level[:1], level.shape)
    return restore(result.loop[:, 0:3], level, result.loop[:, hc], result.travel[:3], float(result.travel[hc]))


def loop_travel(result: CycleResult, perf: Performance) -> tuple[NDArray[np.float64], float]:
    """World travel and heading change (radians about +Y) of one cycle of the loop clip."""
    level = result.loop[:, 3:7] if 0 in perf.joints else np.tile(quat_identity(), (len(result.loop), 1))
    travel = _world_root(result, perf, level)[2]
    return travel, float(result.travel[perf.heading]) if perf.heading is not None else 0.0


def quat_identity() -> NDArray[np.float64]:
    """The identity rotation ``(1, 0, 0, 0)``."""
    return np.array([1.0, 0.0, 0.0, 0.0])


def _in_place(clip: Clip, curve: RootCurve | None, travel: NDArray[np.float64]) -> tuple[Clip, RootCurve | None]:
    """A travelling loop as the game plays it: its travel as root motion, its root (and root curve) in place.

    Written with the travel in the root track, a walk opened in ``author edit`` would jump
    back a stride at every seam (speeds up to 150 m/s, the figure walking off the view);
    split like this it plays in place over the origin like the built-in cycles. The
    extractor's root curve is ``spline + (k/n)·travel``, so taking the same ramp (and
    start) out of both keeps it exact.
    """
    if not np.linalg.norm(travel[[0, 2]]) > 0:
        return clip, curve
    ground = travel * [1.0, 0.0, 1.0]
    start = clip.root[0] * [1.0, 0.0, 1.0]  # the in-place root starts over the origin; so does the curve
    return (
        clip.travel_as_root_motion(ground),
        None if curve is None else RootCurve(curve.control - start, travel - ground),
    )


def save_loop(
    result: CycleResult,
    perf: Performance,
    path: str | Path,
    fps: float | None = None,
    closing_frame: bool | None = None,
) -> Path:
    """Write the loop as ``.bvh``, ``.ppclip``, ``.glb``/``.gltf`` (skeletal input), ``.csv`` or ``.npz``, atomically.

    BVH and glTF loops are resampled to a whole number of frames at ``fps`` (default: the
    source's nominal rate, see :mod:`engine.io.loop_export`); a BVH loop ends with a closing
    frame unless ``closing_frame`` is False (glTF loops always repeat their first key).
    """
    path = Path(path)
    fmt = motion_format(path)
    if fmt is None or path.suffix.lower() not in OUTPUT_SUFFIXES:
        raise TrajectoryError(
            f"{path}: unknown output type {path.suffix.lower()!r}; use one of {', '.join(OUTPUT_SUFFIXES)}"
        )
    if fmt.name == "ppclip":
        from authoring.cycles.root_curve import loop_root_curve
        from engine.clipfile import save_clip

        clip = loop_clip(result, perf)
        clip, curve = _in_place(clip, loop_root_curve(result, perf, clip), loop_travel(result, perf)[0])
        return save_clip(clip, path, root_curve=curve)
    if fmt.skeletal:  # BVH, glTF: another tool's loop, at a whole number of frames
        from engine.io.bvh import write_bvh
        from engine.io.bvh_convert import clip_to_bvh
        from engine.io.gltf_write import write_gltf
        from engine.io.loop_export import closed, loop_at_rate, nominal_rate

        clip = loop_clip(result, perf)
        travel, turn = loop_travel(result, perf)
        assert perf.clip is not None  # a skeletal performance keeps its clip
        clip, travel = loop_at_rate(clip, fps or nominal_rate(perf.clip.fps), travel, turn)
        if fmt.name != "bvh":
            return write_gltf(path, clip)
        return write_bvh(path, clip_to_bvh(closed(clip, travel, turn) if closing_frame is not False else clip))
    if fmt.name == "csv":
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(["time", *perf.names])
        for t, row in zip(result.loop_times, result.loop, strict=True):
            w.writerow([repr(float(t)), *(repr(float(x)) for x in row)])
        return atomic_write_bytes(path, buf.getvalue().encode())
    out = io.BytesIO()
    np.savez_compressed(
        out,
        times=result.loop_times,
        values=result.loop,
        names=np.array(perf.names),
        period=np.float64(result.period),
        travel=result.travel,
    )
    return atomic_write_bytes(path, out.getvalue())
