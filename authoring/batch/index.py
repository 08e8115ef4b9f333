"""The clip library's index: ``LIBDIR/index.sqlite``, what a user asks of a library of loops.

SQLite (the standard library's ``sqlite3``) rather than Parquet: the questions are
filters and joins — walks between 1 and 1.5 m/s, everything from a source under a
licence, the takes refused and why — and one transaction per take is what makes a
killed batch resumable: a take is either fully in the index (its clip files were
written, atomically, before the commit) or not at all, and then it is done again.

Tables (read them with any SQLite tool, or with :func:`read_index`):

* ``takes`` — one row per input content hash: source path, licence, outcome
  (``looped`` / ``refused`` / ``failed``), reason, frames, fps, dims, seconds spent;
* ``clips`` — one row per loop: file (relative to ``LIBDIR``), take hash, segment
  number, start/end frame and seconds in the take, kind, period, cycles, closure
  error, spread, speed (m/s, skeletal takes), dims, source, licence, the clip file's
  SHA-256;
* ``sources`` — path, size, mtime and hash of every input seen, so an unchanged file
  is not read again to learn that it is already done;
* ``meta`` — the schema version and the options the library was built with.

Trust: SQLite keeps no checksum of the values it stores, so the index is checked before
a batch relies on it: ``PRAGMA quick_check`` at open (a damaged page is refused in one
line), and :meth:`LibraryIndex.known_hashes` counts a take as done only while every clip
file it names is there with the SHA-256 the index recorded. A deleted or altered clip
file, or a flipped byte in a clip's row, makes its take be done again.
"""

from __future__ import annotations

import hashlib
import sqlite3
from dataclasses import dataclass
from pathlib import Path

from authoring.batch.worker import TakeOutcome

__all__ = ["INDEX_NAME", "SCHEMA_VERSION", "ClipEntry", "LibraryIndex", "LibraryIndexError", "TakeEntry", "read_index"]

INDEX_NAME = "index.sqlite"
SCHEMA_VERSION = 1

_SCHEMA = """
CREATE TABLE IF NOT EXISTS meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS takes (
    hash TEXT PRIMARY KEY, source TEXT NOT NULL, licence TEXT NOT NULL,
    outcome TEXT NOT NULL CHECK (outcome IN ('looped', 'refused', 'failed')), reason TEXT NOT NULL,
    frames INTEGER NOT NULL, fps REAL NOT NULL, dims INTEGER NOT NULL, clips INTEGER NOT NULL, seconds REAL NOT NULL
);
CREATE TABLE IF NOT EXISTS clips (
    file TEXT PRIMARY KEY, take TEXT NOT NULL REFERENCES takes (hash), segment INTEGER NOT NULL,
    start_frame INTEGER NOT NULL, end_frame INTEGER NOT NULL, start_s REAL NOT NULL, end_s REAL NOT NULL,
    kind TEXT NOT NULL, period REAL NOT NULL, cycles INTEGER NOT NULL, closure_error REAL NOT NULL,
    spread REAL NOT NULL, speed REAL, dims INTEGER NOT NULL, source TEXT NOT NULL, licence TEXT NOT NULL,
    sha256 TEXT NOT NULL
);
CREATE INDEX IF NOT EXISTS clips_kind ON clips (kind, speed);
CREATE TABLE IF NOT EXISTS sources (path TEXT PRIMARY KEY, size INTEGER NOT NULL, mtime_ns INTEGER NOT NULL, hash TEXT NOT NULL);
"""


class LibraryIndexError(ValueError):
    """An index that cannot be used: not an index, a newer schema, or built with other options."""


@dataclass(frozen=True)
class TakeEntry:
    """A row of ``takes``."""

    hash: str
    source: str
    licence: str
    outcome: str
    reason: str
    frames: int
    fps: float
    dims: int
    clips: int
    seconds: float


@dataclass(frozen=True)
class ClipEntry:
    """A row of ``clips``; ``path`` is the clip file's absolute path."""

    file: str
    take: str
    segment: int
    start_frame: int
    end_frame: int
    start_s: float
    end_s: float
    kind: str
    period: float
    cycles: int
    closure_error: float
    spread: float
    speed: float | None
    dims: int
    source: str
    licence: str
    sha256: str
    path: Path


def _connect(path: Path) -> sqlite3.Connection:
    con = sqlite3.connect(path, timeout=30.0)
    con.execute("PRAGMA journal_mode=WAL")  # readers (clips add, a game) never block the batch
    con.execute("PRAGMA synchronous=FULL")  # a committed take survives a power cut, not only kill -9
    return con


class LibraryIndex:
    """The index of one library folder, opened for writing by the batch (one writer)."""

    def __init__(self, libdir: Path, options_key: str) -> None:
        self.libdir = libdir
        self.path = libdir / INDEX_NAME
        try:
            self.con = _connect(self.path)
            damage = [str(row[0]) for row in self.con.execute("PRAGMA quick_check").fetchall()]
            if damage != ["ok"]:
                self.con.close()
                raise LibraryIndexError(f"{self.path} is damaged ({'; '.join(damage)[:120]}); move it away "
                                        "and run cycles again to rebuild it from the clip files' sources")
            self.con.executescript(_SCHEMA)
            meta = dict(self.con.execute("SELECT key, value FROM meta").fetchall())
        except sqlite3.DatabaseError as exc:
            raise LibraryIndexError(f"{self.path} is not a library index ({exc})") from None
        schema = str(meta.get("schema", SCHEMA_VERSION))
        if not schema.isdigit():
            raise LibraryIndexError(f"{self.path} has schema {schema[:20]!r}, not a version number")
        version = int(schema)
        if version > SCHEMA_VERSION:
            raise LibraryIndexError(f"{self.path} has schema {version}; this puppetphone reads up to {SCHEMA_VERSION}")
        built = meta.get("options")
        if built is not None and built != options_key:
            raise LibraryIndexError(f"{self.libdir} was built with {built}; use the same options or another -o")
        with self.con:
            self.con.execute("INSERT OR IGNORE INTO meta VALUES ('schema', ?)", (str(SCHEMA_VERSION),))
            self.con.execute("INSERT OR IGNORE INTO meta VALUES ('options', ?)", (options_key,))

    def close(self) -> None:
        """Close the connection (everything recorded is committed already)."""
        self.con.close()

    def known_hashes(self, failed: bool = True) -> set[str]:
        """Content hashes of every take done: in the index, with each clip file it names intact
        (without the takes that failed, unless ``failed``: ``cycles --retry-failed``).

        A take whose clip count, clip files or their SHA-256 no longer match (a file deleted or
        changed, a damaged row) is left out, so the batch does it again and rewrites its rows.
        """
        query = "SELECT hash, clips FROM takes" + ("" if failed else " WHERE outcome != 'failed'")
        try:
            takes = dict(self.con.execute(query).fetchall())
            rows = self.con.execute("SELECT take, file, sha256 FROM clips").fetchall()
        except sqlite3.DatabaseError as exc:
            raise LibraryIndexError(f"{self.path} is not a readable library index ({exc})") from None
        found: dict[str, int] = {}
        for take, file, digest in rows:
            if take in takes and self._intact(str(file), str(digest)):
                found[take] = found.get(take, 0) + 1
        return {h for h, n in takes.items() if found.get(h, 0) == n}

    def _intact(self, file: str, digest: str) -> bool:
        """Whether the clip file ``file`` (relative to the library) is there with SHA-256 ``digest``."""
        path = self.libdir / file
        if Path(file).is_absolute() or ".." in Path(file).parts:
            return False
        try:
            with open(path, "rb") as f:
                return hashlib.file_digest(f, "sha256").hexdigest() == digest
        except OSError:
            return False

    def cached_hash(self, path: str, size: int, mtime_ns: int) -> str | None:
        """The hash recorded for ``path`` if its size and mtime are unchanged."""
        row = self.con.execute("SELECT hash FROM sources WHERE path = ? AND size = ? AND mtime_ns = ?",
                               (path, size, mtime_ns)).fetchone()
        return None if row is None else str(row[0])

    def remember_source(self, path: str, size: int, mtime_ns: int, digest: str) -> None:
        """Note a source's hash (committed with the next take, or by :meth:`commit`)."""
        self.con.execute("INSERT OR REPLACE INTO sources VALUES (?, ?, ?, ?)", (path, size, mtime_ns, digest))

    def commit(self) -> None:
        """Commit pending source notes."""
        self.con.commit()

    def record(self, outcome: TakeOutcome, files: list[str], licence: str) -> None:
        """One take and its clips, in one transaction (``files`` already written, relative to the library)."""
        with self.con:
            self.con.execute("DELETE FROM clips WHERE take = ?", (outcome.digest,))
            self.con.execute(
                "INSERT OR REPLACE INTO takes VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
                (outcome.digest, outcome.source, licence, outcome.outcome, outcome.reason, outcome.frames,
                 outcome.fps, outcome.dims, len(outcome.clips), outcome.seconds),
            )
            for clip, file in zip(outcome.clips, files, strict=True):
                self.con.execute(
                    "INSERT OR REPLACE INTO clips VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
                    (file, outcome.digest, clip.segment, clip.start_frame, clip.end_frame, clip.start_s, clip.end_s,
                     clip.kind, clip.period, clip.cycles, clip.closure_error, clip.spread, clip.speed, clip.dims,
                     outcome.source, licence, hashlib.sha256(clip.data).hexdigest()),
                )


def read_index(libdir: str | Path) -> tuple[list[TakeEntry], list[ClipEntry]]:
    """Every take and clip of a library, sorted by source then position (for ``clips add``, the games' library).

    Raises:
        LibraryIndexError: no index in ``libdir``, or not a readable one.
    """
    libdir = Path(libdir)
    path = libdir / INDEX_NAME
    if not path.is_file():
        raise LibraryIndexError(f"no library index in {libdir} (make one with: puppetphone cycles SRC... -o {libdir})")
    try:
        con = sqlite3.connect(f"file:{path}?mode=ro", uri=True, timeout=30.0)
        try:
            cur = con.execute("SELECT * FROM takes ORDER BY source, hash")
            names = [d[0] for d in cur.description]
            takes = [TakeEntry(**dict(zip(names, row, strict=True))) for row in cur]
            cur = con.execute("SELECT * FROM clips ORDER BY source, start_frame, file")
            names = [d[0] for d in cur.description]
            clips = [ClipEntry(**dict(zip(names, row, strict=True)), path=libdir / row[0]) for row in cur]
        finally:
            con.close()
    except sqlite3.DatabaseError as exc:
        raise LibraryIndexError(f"{path} is not a readable library index ({exc})") from None
    return takes, clips
