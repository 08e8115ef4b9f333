"""The batch: which takes to do, who does them (here, a process pool, a Dask cluster), and the library.

    plan = plan_batch(sources, index)          # every input hashed; the ones already indexed skipped
    for outcome in run_tasks(plan.tasks, ...): # the same worker function on any scheduler
        library.add(outcome)                   # clip files atomically, then one index transaction

Only this process writes the library. Workers get a :class:`~authoring.batch.worker.TakeTask`
(a path on a shared file system, or the bytes) and return a
:class:`~authoring.batch.worker.TakeOutcome` with the clips as bytes. Outcomes arrive in
any order; nothing written depends on that order (file names come from the content hash,
rows are keyed by it), so a run with one job, eight, or a cluster builds the same index.
"""

from __future__ import annotations

import glob
import hashlib
import multiprocessing
import os
import time
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, field
from pathlib import Path

from authoring.batch.index import LibraryIndex
from authoring.batch.worker import BatchOptions, TakeOutcome, TakeTask, process_take, warm_up
from engine.atomic import atomic_write_bytes

__all__ = [
    "BatchError",
    "Library",
    "Plan",
    "SourceError",
    "collect_sources",
    "default_jobs",
    "file_hash",
    "licence_of",
    "plan_batch",
    "run_tasks",
]

CLIPS_DIR = "clips"
WATCH_EVERY = 0.5  # seconds between a pool worker's checks that the main process is alive
_CHUNK = 1 << 20

# Licences of the public sets whose file names say where they come from; anything else is "unknown"
# unless --licence says. Bandai's sets are non-commercial: a library built from them must say so.
KNOWN_LICENCES = (
    ("bandai", "CC BY-NC 4.0 (Bandai Namco Research Motiondataset)"),
    ("cmu", "CMU Graphics Lab Motion Capture Database terms: free for research and commercial use"),
)


class SourceError(ValueError):
    """A source argument that names nothing to read, or a scheduler that cannot be used."""


class BatchError(RuntimeError):
    """The workers were lost (a process killed, a cluster gone); what was recorded stays, a rerun resumes."""


def licence_of(path: str, given: str | None) -> str:
    """The licence to record for a take: ``--licence``, else a known set's by file name, else ``unknown``."""
    if given:
        return given
    name = Path(path).name.lower()
    for prefix, text in KNOWN_LICENCES:
        if name.startswith(prefix):
            return text
    return "unknown"


def collect_sources(args: Iterable[str], suffixes: Iterable[str], exclude: Path | None = None) -> list[Path]:
    """Files, folders (searched recursively for ``suffixes``) and glob patterns, in a stable order, once each.

    Files under ``exclude`` (the library being written, when it sits inside a source
    folder) are left out: its own loops are not takes.

    Raises:
        SourceError: an argument that matches no readable file.
    """
    wanted = tuple(s.lower() for s in suffixes)
    out: dict[Path, None] = {}
    for arg in args:
        p = Path(arg)
        if p.is_dir():
            found = sorted(f for f in p.rglob("*") if f.is_file() and f.suffix.lower() in wanted)
        elif p.is_file():
            found = [p]
        else:
            found = sorted(Path(f) for f in glob.glob(arg, recursive=True) if Path(f).is_file())
            if not found:
                raise SourceError(f"{arg}: no such file, folder, or matching file")
        skip = exclude.resolve() if exclude is not None else None
        for f in found:
            f = f.resolve()
            if skip is None or not f.is_relative_to(skip):
                out.setdefault(f, None)
    return list(out)


def file_hash(path: Path) -> str:
    """SHA-256 of a file's bytes."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        while chunk := fh.read(_CHUNK):
            h.update(chunk)
    return h.hexdigest()


@dataclass
class Plan:
    """What a run will do: the tasks, and what it skips."""

    tasks: list[TakeTask] = field(default_factory=list)
    already: int = 0  # takes whose content is in the index
    duplicates: int = 0  # files with the same content as another in this run
    unreadable: list[tuple[str, str]] = field(default_factory=list)  # (path, reason)


def plan_batch(sources: list[Path], index: LibraryIndex, retry_failed: bool = False) -> Plan:
    """Hash every source (or reuse the hash of an unchanged file) and keep those not in the index.

    With ``retry_failed`` a take recorded as failed (unreadable, or a reader bug since fixed)
    is done again; looped and refused takes never are.
    """
    known = index.known_hashes(failed=not retry_failed)
    plan = Plan()
    seen: set[str] = set()
    for path in sources:
        try:
            st = path.stat()
            digest = index.cached_hash(str(path), st.st_size, st.st_mtime_ns)
            if digest is None:
                digest = file_hash(path)
                index.remember_source(str(path), st.st_size, st.st_mtime_ns, digest)
        except OSError as exc:
            plan.unreadable.append((str(path), exc.strerror or str(exc)))
            continue
        if digest in known:
            plan.already += 1
        elif digest in seen:
            plan.duplicates += 1
        else:
            seen.add(digest)
            plan.tasks.append(TakeTask(str(path), digest))
    index.commit()
    return plan


class Library:
    """The library folder being written: clip files, then the index row, per take."""

    def __init__(self, libdir: Path, index: LibraryIndex, licence: str | None) -> None:
        self.libdir = libdir
        self.index = index
        self.licence = licence
        (libdir / CLIPS_DIR).mkdir(parents=True, exist_ok=True)

    def add(self, outcome: TakeOutcome) -> list[str]:
        """Write the take's clips atomically, then record it; returns the clip files (relative to the library)."""
        stem = Path(outcome.source).stem
        files = []
        for clip in outcome.clips:
            rel = f"{CLIPS_DIR}/{stem}-{outcome.digest[:12]}-{clip.segment}{clip.suffix}"
            atomic_write_bytes(self.libdir / rel, clip.data)
            files.append(rel)
        self.index.record(outcome, files, licence_of(outcome.source, self.licence))
        return files


def run_tasks(
    tasks: list[TakeTask],
    options: BatchOptions,
    jobs: int = 1,
    scheduler: str | None = None,
    on_start: Callable[[int], None] | None = None,
    send_bytes: bool = False,
) -> Iterator[TakeOutcome]:
    """Process the tasks and yield each outcome as it arrives.

    ``scheduler`` (a Dask address, ``tcp://host:8786``) sends every task to the cluster,
    a few per worker at a time (with ``send_bytes``, each take's bytes, read as it is
    sent, for workers that cannot read the path); otherwise ``jobs > 1`` runs a process
    pool of that many workers (each imports the heavy modules once, at start) and
    ``jobs == 1`` runs them here, one after another. ``on_start`` is told the number of
    workers once they are up.
    """
    if not tasks:
        return
    if scheduler:
        yield from _dask(tasks, options, scheduler, on_start, send_bytes)
    elif jobs > 1 and len(tasks) > 1:
        yield from _pool(tasks, options, min(jobs, len(tasks)), on_start)
    else:
        warm_up()
        if on_start:
            on_start(1)
        for task in tasks:
            yield process_take(task, options)


def _pool(
    tasks: list[TakeTask], options: BatchOptions, jobs: int, on_start: Callable[[int], None] | None
) -> Iterator[TakeOutcome]:
    # forkserver: workers start from a clean process, not a fork of one that may hold threads (a progress bar's).
    ctx = multiprocessing.get_context("forkserver")
    with ProcessPoolExecutor(
        max_workers=jobs, mp_context=ctx, initializer=_start_worker, initargs=(os.getpid(),)
    ) as pool:
        if on_start:
            on_start(jobs)
        futures = [pool.submit(process_take, task, options) for task in tasks]
        try:
            for fut in as_completed(futures):
                try:
                    outcome = fut.result()
                except BrokenProcessPool as exc:  # a worker was killed (out of memory, a signal)
                    raise BatchError(f"a worker process died ({exc})") from None
                yield outcome
        finally:
            for fut in futures:
                fut.cancel()


def _start_worker(main_pid: int) -> None:
    """A pool worker's start: the heavy imports, and a watch on the batch's main process.

    A worker waiting for work never learns that the main process was killed (``kill -9``):
    the pool's queue just stays silent, and four workers of ~110 MB each were still alive
    90 s later. The watch ends the worker within a second of the main process going.
    """
    import threading

    def watch() -> None:
        while True:
            time.sleep(WATCH_EVERY)
            try:
                os.kill(main_pid, 0)
            except ProcessLookupError:
                os._exit(1)
            except PermissionError:
                pass  # exists, under another user: not ours to judge

    threading.Thread(target=watch, name="main-process-watch", daemon=True).start()
    warm_up()


def _dask(
    tasks: list[TakeTask], options: BatchOptions, address: str, on_start: Callable[[int], None] | None, send_bytes: bool
) -> Iterator[TakeOutcome]:
    try:
        from distributed import Client
        from distributed import as_completed as dask_completed
    except ImportError:
        raise SourceError("--scheduler needs Dask's distributed: pip install 'puppetphone[cluster]'") from None
    try:
        client = Client(address, timeout="20s")
    except (OSError, TimeoutError) as exc:
        raise SourceError(f"cannot reach the Dask scheduler at {address}: {exc}") from None
    try:
        client.run(warm_up)  # heavy imports once on every worker, before the tasks
        workers = len(client.scheduler_info().get("workers", {}))
        if on_start:
            on_start(workers)
        pending = iter(tasks)
        running = dask_completed()
        submitted = []

        def submit_next() -> None:
            task = next(pending, None)
            if task is None:
                return
            if send_bytes:  # read only now: a library's bytes never sit in memory all at once
                task = TakeTask(task.source, task.digest, Path(task.source).read_bytes())
            fut = client.submit(process_take, task, options, key=f"take-{task.digest}-{options.key()}", pure=False)
            submitted.append(fut)
            running.add(fut)

        for _ in range(max(2, 4 * workers)):  # enough queued to keep every worker busy
            submit_next()
        try:
            for fut in running:
                try:
                    outcome = fut.result()
                except Exception as exc:  # noqa: BLE001 -- process_take never raises: this is the cluster (KilledWorker…)
                    raise BatchError(f"the cluster lost a task: {type(exc).__name__}: {exc}") from None
                fut.release()
                submit_next()
                yield outcome
        finally:
            client.cancel([f for f in submitted if not f.done()])
    finally:
        client.close()


def default_jobs() -> int:
    """Worker processes by default: every core this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not Linux
        return max(1, os.cpu_count() or 1)
