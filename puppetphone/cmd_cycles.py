"""``puppetphone cycles SRC... -o LIBDIR``: a mocap library in, a library of loops and its index out.

Sources are files, folders (searched recursively for the input types ``cycle`` reads)
and glob patterns. Every take is extracted — each looping segment of a take of several
activities — into ``LIBDIR/clips/`` and recorded in ``LIBDIR/index.sqlite``
(:mod:`authoring.batch.index`). One line per take on standard output (looped: period,
cycles, closure error, speed, dims; refused or failed: the reason), a progress bar on a
terminal, and a summary line last::

    cycles: 6 looped (7 clips), 2 refused, 1 failed, 0 already done, in 14.2 s -> lib

A take whose content is already in the index is skipped, so a second run does nothing
and says so, and a run that was killed resumes where it stopped; ``--retry-failed`` does
the takes recorded as failed again. Exit status: 0 when every take was looped, refused or
skipped; 3 when the run finished but some takes could not be read or analysed (listed as
failed); 1 when the run itself failed (its workers lost: run again to resume); 2 for bad
arguments.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # imported inside run(): `puppetphone --help` stays instant
    from rich.progress import Progress

    from authoring.batch.worker import TakeOutcome

__all__ = ["configure", "run"]

EXIT_BAD_INPUT = 2
EXIT_RUN_FAILED = 1
EXIT_SOME_FAILED = 3


def configure(parser: argparse.ArgumentParser) -> None:
    """Add the cycles arguments."""
    from puppetphone.argtypes import int_range

    parser.add_argument("sources", nargs="+", metavar="SRC", help="takes: files, folders (recursive) or glob patterns")
    parser.add_argument("-o", "--output", required=True, metavar="LIBDIR", help="library folder (made if missing)")
    parser.add_argument(
        "--jobs",
        "-j",
        type=int_range(1, 1024),
        metavar="N",
        help="worker processes on this machine (default: every core)",
    )
    parser.add_argument(
        "--scheduler", metavar="ADDRESS", help="run on a Dask cluster, e.g. tcp://host:8786 (needs the 'cluster' extra)"
    )
    parser.add_argument(
        "--send-bytes",
        action="store_true",
        help="send each take's bytes to the workers (when they do not share this file system)",
    )
    parser.add_argument("--retarget", choices=["puppet"], help="retarget skeletal loops to the puppet's skeleton")
    parser.add_argument(
        "--licence",
        metavar="TEXT",
        help="licence recorded for every take (default: known sets by file name, else 'unknown')",
    )
    parser.add_argument(
        "--no-segments", action="store_true", help="one loop per take: do not look for several activities"
    )
    parser.add_argument("--seed", type=int, default=0, help="seed of the extractor's probe points (default 0)")
    parser.add_argument("--no-progress", action="store_true", help="never show the progress bar")
    parser.add_argument(
        "--retry-failed",
        action="store_true",
        help="do again the takes a previous run recorded as failed (looped and refused ones stay)",
    )
    parser.epilog = (
        f"exit codes: 0 every take looped, refused or already done; {EXIT_SOME_FAILED} done, but some "
        f"takes could not be read or analysed (listed as failed); {EXIT_RUN_FAILED} the run failed "
        f"(run again to resume); {EXIT_BAD_INPUT} bad arguments"
    )


def _line(outcome: TakeOutcome, files: list[str]) -> list[str]:
    """The per-take lines: one per clip, or one with the reason."""
    name = Path(outcome.source).name
    lines = [f"note     {name}: {outcome.note}"] if outcome.note else []
    if outcome.outcome != "looped":
        return [*lines, f"{outcome.outcome:<8} {name}: {outcome.reason}"]
    for clip, file in zip(outcome.clips, files, strict=True):
        part = "" if len(outcome.clips) == 1 and clip.start_frame <= 5 else f" [{clip.start_s:.2f}–{clip.end_s:.2f} s]"
        part = f" [{clip.animation}]" if clip.animation is not None else part
        speed = "" if clip.speed is None else f", {clip.speed:.2f} m/s"
        lines.append(
            f"looped   {name}{part}: {clip.kind}, period {clip.period:.3f} s, {clip.cycles} cycles, "
            f"closure error {clip.closure_error:.1e}{speed}, {clip.dims} dims -> {file}"
        )
    return lines


def _progress(enabled: bool) -> Progress:
    """A rich progress bar on standard error (disabled off a terminal); per-take lines print above it."""
    from rich.console import Console
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    return Progress(
        TextColumn("[progress.description]{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
        TimeRemainingColumn(),
        console=Console(stderr=True),
        disable=not enabled,
    )


def run(args: argparse.Namespace) -> int:
    """Plan, extract on the chosen scheduler, write the library, summarise."""
    from authoring.batch.index import LibraryIndex, LibraryIndexError
    from authoring.batch.runner import (
        BatchError,
        Library,
        SourceError,
        collect_sources,
        default_jobs,
        plan_batch,
        run_tasks,
    )
    from authoring.batch.worker import BatchOptions
    from authoring.cycles.formats import INPUT_SUFFIXES

    t0 = time.perf_counter()
    if args.send_bytes and not args.scheduler:
        print("cycles: --send-bytes sends takes to a Dask cluster's workers; give --scheduler too", file=sys.stderr)
        return EXIT_BAD_INPUT
    libdir = Path(args.output)
    options = BatchOptions(retarget=args.retarget, segments=not args.no_segments, seed=args.seed)
    try:
        sources = collect_sources(args.sources, INPUT_SUFFIXES, exclude=libdir)
        if libdir.exists() and not libdir.is_dir():
            raise SourceError(f"{libdir} is not a folder")
        libdir.mkdir(parents=True, exist_ok=True)
        index = LibraryIndex(libdir, options.key())
    except (SourceError, LibraryIndexError, OSError) as exc:
        print(f"cycles: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    try:
        plan = plan_batch(sources, index, retry_failed=args.retry_failed)
        for path, reason in plan.unreadable:
            print(f"failed   {Path(path).name}: cannot read: {reason}")
        if not plan.tasks:
            print(
                f"cycles: nothing to do: {plan.already} take(s) already in {index.path}"
                + (f", {plan.duplicates} duplicate(s)" if plan.duplicates else "")
                + (f", {len(plan.unreadable)} unreadable" if plan.unreadable else "")
            )
            return EXIT_SOME_FAILED if plan.unreadable else 0
        library = Library(libdir, index, args.licence)
        counts = {"looped": 0, "refused": 0, "failed": len(plan.unreadable)}
        clips = 0
        bar = _progress(not args.no_progress and sys.stderr.isatty())
        with bar:
            task = bar.add_task("starting workers", total=len(plan.tasks))

            def started(workers: int) -> None:
                bar.update(task, description=f"cycles ({workers} worker{'s' if workers != 1 else ''})")

            jobs = args.jobs or default_jobs()
            for outcome in run_tasks(
                plan.tasks, options, jobs=jobs, scheduler=args.scheduler, on_start=started, send_bytes=args.send_bytes
            ):
                files = library.add(outcome)
                counts[outcome.outcome] += 1
                clips += len(files)
                for line in _line(outcome, files):
                    print(line, flush=True)
                bar.advance(task)
    except SourceError as exc:
        print(f"cycles: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except BatchError as exc:
        print(f"cycles: {exc}; the takes done so far are in {index.path}: run again to resume", file=sys.stderr)
        return EXIT_RUN_FAILED
    finally:
        index.close()
    skipped = f"{plan.already} already done" + (f", {plan.duplicates} duplicate(s)" if plan.duplicates else "")
    print(
        f"cycles: {counts['looped']} looped ({clips} clips), {counts['refused']} refused, {counts['failed']} failed, "
        f"{skipped}, in {time.perf_counter() - t0:.1f} s -> {libdir}"
    )
    return EXIT_SOME_FAILED if counts["failed"] else 0
