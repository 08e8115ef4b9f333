"""One take in, its loops (or the reason there are none) out: the task every scheduler runs.

:func:`process_take` is a pure function of the take's bytes and the options. It reads
nothing but its input, writes nothing at all, and returns the clips *as bytes* in a
picklable :class:`TakeOutcome`: the same code runs in this process, in a process pool,
or on a Dask worker on another machine, and only the process that owns the library
writes files and the index. It never raises for a bad take — a file that cannot be
read or analysed comes back as ``failed`` with the reason, so one bad file never stops
a batch.

Segments (:mod:`authoring.cycles.segments`): a take in which several looping
activities are found gives one clip per activity that loops; a take of one activity is
extracted whole, and if that is refused, from the one segment found in it.

Animations: every animation of a glTF file is a take of its own (Fox's Survey, Walk and
Run), its clips numbered on after the previous animation's and named by it.
"""

from __future__ import annotations

import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # the heavy modules are imported by the worker when it starts (warm_up), not by the CLI
    from authoring.cycles.extract import CycleResult
    from authoring.cycles.formats import Performance
    from authoring.cycles.segments import Segment

__all__ = ["KINDS_BY_NAME", "BatchOptions", "ClipOut", "TakeOutcome", "TakeTask", "process_take", "warm_up"]

# Motion kinds a file name may announce, first match wins (CMU, Bandai and studio names use these words).
KINDS_BY_NAME = (
    ("walk", ("walk",)),
    ("run", ("run", "jog", "sprint")),
    ("crouch", ("crouch", "sneak")),
    ("jump", ("jump", "hop")),
    ("punch", ("punch", "strike", "box")),
    ("kick", ("kick",)),
    ("dance", ("dance", "salsa", "waltz")),
    ("idle", ("idle", "stand")),
)
WALK_MIN_SPEED = 0.2  # m/s: below, an in-place motion
RUN_MIN_SPEED = 1.9  # m/s: the walk–run transition of adults is near 2 m/s


@dataclass(frozen=True)
class BatchOptions:
    """What shapes the outputs; a library is built with one set of them (the index keeps it).

    Attributes:
        retarget: ``"puppet"`` to retarget skeletal loops to the puppet's skeleton, else ``None``.
        segments: look for several looping activities in a take.
        seed: seed of the extractor's probe points (results are reproducible).
    """

    retarget: str | None = None
    segments: bool = True
    seed: int = 0

    def key(self) -> str:
        """The options as a stable string, stored in the index."""
        return f"retarget={self.retarget or 'none'};segments={int(self.segments)};seed={self.seed}"


@dataclass(frozen=True)
class TakeTask:
    """A take to process: its path, its content hash, and its bytes when the workers cannot read the path."""

    source: str
    digest: str
    data: bytes | None = None


@dataclass(frozen=True)
class ClipOut:
    """One extracted loop: where in the take, what it measured, and the clip file's bytes."""

    segment: int
    start_frame: int
    end_frame: int
    start_s: float
    end_s: float
    period: float
    cycles: int
    closure_error: float
    spread: float
    speed: float | None
    dims: int
    kind: str
    suffix: str
    data: bytes = field(repr=False)
    animation: str | None = None


@dataclass(frozen=True)
class TakeOutcome:
    """What became of one take: ``looped`` (with clips), ``refused`` (no loop: the reason) or ``failed``."""

    source: str
    digest: str
    outcome: str
    reason: str
    frames: int
    fps: float
    dims: int
    seconds: float
    clips: tuple[ClipOut, ...] = ()
    note: str = ""
    """How the figure was sized when no unit fitted it (a hand, a figure without legs), else empty."""


def warm_up() -> None:
    """Import the heavy modules once per worker process, before the first take arrives."""
    import authoring.cycles.extract
    import authoring.cycles.formats
    import authoring.cycles.segments  # noqa: F401
    import engine.clipfile
    import engine.io.bvh
    import engine.io.retarget  # noqa: F401


def _load(path: Path, animation: int | None = None) -> Performance:
    """The one place a take is read (the loader that knows every input format); ``animation``: a glTF's."""
    from authoring.cycles.formats import load_performance

    return load_performance(path, animation=animation)


def kind_of(name: str, speed: float | None) -> str:
    """The motion's kind: a word of the file name, else the travel speed (walk, run, in place), else unknown."""
    low = name.lower()
    for kind, words in KINDS_BY_NAME:
        if any(w in low for w in words):
            return kind
    if speed is None:
        return "unknown"
    if speed < WALK_MIN_SPEED:
        return "in place"
    return "walk" if speed < RUN_MIN_SPEED else "run"


def _clip_bytes(result: CycleResult, perf: Performance, retarget: str | None, workdir: Path) -> tuple[str, bytes]:
    """The loop in the project's clip format: ``.ppclip`` for skeletal takes (retargeted if asked), else ``.npz``."""
    from authoring.cycles.formats import loop_clip, save_loop
    from engine.clipfile import save_clip

    if perf.clip is None:
        out = save_loop(result, perf, workdir / "loop.npz")
        return ".npz", out.read_bytes()
    clip = loop_clip(result, perf)
    if retarget == "puppet":
        from engine.io.motion_file import to_puppet

        clip, _ = to_puppet(clip)  # the name maps every command uses
    return ".ppclip", save_clip(clip, workdir / "loop.ppclip").read_bytes()


def _speed(result: CycleResult, perf: Performance) -> float | None:
    """Horizontal root travel per second (m/s, Y up) for skeletal takes; None for other inputs."""
    if perf.clip is None:
        return None
    import math

    return math.hypot(float(result.travel[0]), float(result.travel[2])) / result.period


def process_take(task: TakeTask, options: BatchOptions) -> TakeOutcome:
    """Extract every loop of one take; never raises for a bad take (see the module docstring).

    BLAS runs one thread for the whole take (the segment search's SVD and products as
    well as the extractor): the parallelism is one take per worker, and a multi-threaded
    BLAS in every worker spins against the others — measured here, two workers took 2.3
    times the CPU of one for the same takes, and with one thread each they run 1.9 times faster.
    """
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1, user_api="blas"):
        return _process(task, options)


def _without_path(error: BaseException, path: Path) -> str:
    """The reader's message without the file's path in front (the take's line names it; a sent take's path is a temp file)."""
    message = str(error)
    if not message.startswith(str(path)):
        return message
    rest = message[len(str(path)) :]
    line, colon, why = rest.lstrip(":").partition(":")
    if colon and line.strip().isdigit():  # "PATH:12: why" -> "line 12: why"
        return f"line {line.strip()}:{why}"
    return rest.lstrip(": ")


def _process(task: TakeTask, options: BatchOptions) -> TakeOutcome:
    t0 = time.perf_counter()
    name = Path(task.source).name
    with tempfile.TemporaryDirectory(prefix="ppcycles-") as tmp:
        workdir = Path(tmp)
        try:
            path = Path(task.source)
            if task.data is not None:
                path = workdir / f"take{Path(task.source).suffix.lower()}"
                path.write_bytes(task.data)
            perf = _load(path)
        except (OSError, ValueError) as exc:  # TrajectoryError and the format errors are ValueErrors
            return TakeOutcome(
                task.source,
                task.digest,
                "failed",
                f"cannot read: {_without_path(exc, path)}"[:500],
                0,
                0.0,
                0,
                time.perf_counter() - t0,
            )
        except Exception as exc:  # noqa: BLE001 -- a reader bug must not stop the batch; the reason names it
            return TakeOutcome(
                task.source,
                task.digest,
                "failed",
                f"cannot read: {type(exc).__name__}: {exc}"[:500],
                0,
                0.0,
                0,
                time.perf_counter() - t0,
            )
        traj = perf.trajectory

        note = (perf.motion.unit_note or "") if perf.motion is not None else ""

        def outcome(kind: str, reason: str, clips: tuple[ClipOut, ...] = ()) -> TakeOutcome:
            return TakeOutcome(
                task.source,
                task.digest,
                kind,
                reason,
                traj.num_samples,
                1.0 / traj.dt,
                traj.dims,
                time.perf_counter() - t0,
                clips,
                note,
            )

        if options.retarget and perf.clip is None:
            return outcome("refused", "--retarget puppet needs a skeletal take (BVH)")
        try:
            clips, reason = _extract_animations(path, perf, options, name, workdir)
        except Exception as exc:  # noqa: BLE001 -- an extractor or retarget bug on one take: reported, the batch goes on
            return outcome("failed", f"{type(exc).__name__}: {exc}"[:500])
    return outcome("looped" if clips else "refused", reason, tuple(clips))


def _extract_animations(
    path: Path, first: Performance, options: BatchOptions, name: str, workdir: Path
) -> tuple[list[ClipOut], str]:
    """:func:`_extract_all` for every animation of a glTF file (one take each), or for the one take of any other."""
    import dataclasses

    names = first.motion.animations if first.motion is not None else ()
    if len(names) < 2:
        return _extract_all(first, options, name, workdir)
    clips: list[ClipOut] = []
    notes: list[str] = []
    for k, animation in enumerate(names):
        perf = first if k == 0 else _load(path, k)
        found, reason = _extract_all(perf, options, f"{name} {animation}", workdir)
        clips += [dataclasses.replace(c, segment=len(clips) + i, animation=animation) for i, c in enumerate(found)]
        if reason:
            notes.append(f"{animation}: {reason}")
    return clips, "; ".join(notes)


def _extract_all(perf: Performance, options: BatchOptions, name: str, workdir: Path) -> tuple[list[ClipOut], str]:
    """Clips of the take (whole, or per segment) and a note: the refusal, or how many segments looped."""
    from authoring.cycles.segments import Segment, find_segments

    traj = perf.trajectory
    segments = find_segments(traj) if options.segments else []
    whole = Segment(0, traj.num_samples, 0.0, float(traj.times[-1] + traj.dt), 0.0, 0.0)
    attempts = [segments] if len(segments) >= 2 else [[whole], segments]
    refusals: list[str] = []
    for plan in attempts:
        clips = []
        for k, seg in enumerate(plan):
            clip = _extract_segment(perf, seg, k, name if len(plan) == 1 else "", options, workdir, refusals)
            if clip is not None:
                clips.append(clip)
        if clips:
            return clips, "" if plan[0] is whole else f"{len(clips)} of {len(plan)} segments loop"
    return [], refusals[0] if refusals else "no cycle"


def _extract_segment(
    perf: Performance, seg: Segment, k: int, name: str, options: BatchOptions, workdir: Path, refusals: list[str]
) -> ClipOut | None:
    """One segment's loop as a :class:`ClipOut`, or ``None`` with its refusal appended to ``refusals``."""
    import dataclasses

    import numpy as np

    from authoring.cycles.extract import CycleError, extract_cycle
    from authoring.cycles.segments import cut

    traj = perf.trajectory
    whole = seg.start == 0 and seg.stop == traj.num_samples
    part = perf if whole else dataclasses.replace(perf, trajectory=cut(traj, seg.start, seg.stop))
    try:
        result = extract_cycle(part.trajectory, np.random.default_rng(options.seed))
    except CycleError as exc:
        refusals.append(str(exc) if whole else f"segment {seg.t0:.2f}–{seg.t1:.2f} s: {exc}")
        return None
    suffix, data = _clip_bytes(result, part, options.retarget, workdir)
    speed = _speed(result, part)
    lead = perf.skipped * traj.dt  # file time of the trajectory's first sample
    return ClipOut(
        segment=k,
        start_frame=seg.start + perf.skipped,
        end_frame=seg.stop + perf.skipped,
        start_s=round(float(traj.times[seg.start]) + lead, 6),
        end_s=round(seg.t1 + lead, 6),
        period=round(result.period, 6),
        cycles=perf.performed or result.cycles,
        closure_error=float(result.closure_error),
        spread=round(result.spread, 6),
        speed=None if speed is None else round(speed, 4),
        dims=traj.dims,
        kind=kind_of(name, speed),
        suffix=suffix,
        data=data,
    )
