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
line), every row of every table carries ``row_sum`` (:mod:`authoring.batch.row_sums`),
checked on every read, and :meth:`LibraryIndex.known_hashes` counts a take as done only
while its rows are intact and every clip file it names is there with the SHA-256 the index
recorded. A flipped byte in a row of ``takes`` or ``clips`` (or a deleted or altered clip
file) makes its take be done again, said in one line (:attr:`LibraryIndex.notices`); in
``sources`` the file is read again instead of trusting its hash; in ``meta`` (the schema
and options) the index is refused in one line. :func:`read_index` (``clips add``, the games)
refuses an index with any damaged row (of any table) in one line. An index of schema 1 (before the row
sums) gets them at its next batch, its rows taken as they are.
"""

from __future__ import annotations

import hashlib
import sqlite3
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from authoring.batch.row_sums import COLUMNS, intact, row_sum, typed
from authoring.batch.worker import TakeOutcome
from engine.errors import FormatError

__all__ = ["INDEX_NAME", "SCHEMA_VERSION", "ClipEntry", "LibraryIndex", "LibraryIndexError", "TakeEntry", "read_index"]

INDEX_NAME = "index.sqlite"
SCHEMA_VERSION = 2  # 2: a row_sum in every row

_SCHEMA = """
CREATE TABLE IF NOT EXISTS meta (key TEXT PRIMARY KEY, value TEXT NOT NULL, row_sum TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS takes (
    hash TEXT PRIMARY KEY, source TEXT NOT NULL, licence TEXT NOT NULL,
    outcome TEXT NOT NULL CHECK (outcome IN ('looped', 'refused', 'failed')), reason TEXT NOT NULL,
    frames INTEGER NOT NULL, fps REAL NOT NULL, dims INTEGER NOT NULL, clips INTEGER NOT NULL, seconds REAL NOT NULL,
    row_sum TEXT NOT NULL
);
CREATE TABLE IF NOT EXISTS clips (
    file TEXT PRIMARY KEY, take TEXT NOT NULL REFERENCES takes (hash), segment INTEGER NOT NULL,
    start_frame INTEGER NOT NULL, end_frame INTEGER NOT NULL, start_s REAL NOT NULL, end_s REAL NOT NULL,
    kind TEXT NOT NULL, period REAL NOT NULL, cycles INTEGER NOT NULL, closure_error REAL NOT NULL,
    spread REAL NOT NULL, speed REAL, dims INTEGER NOT NULL, source TEXT NOT NULL, licence TEXT NOT NULL,
    sha256 TEXT NOT NULL, row_sum TEXT NOT NULL
);
CREATE INDEX IF NOT EXISTS clips_kind ON clips (kind, speed);
CREATE TABLE IF NOT EXISTS sources (path TEXT PRIMARY KEY, size INTEGER NOT NULL, mtime_ns INTEGER NOT NULL,
                                    hash TEXT NOT NULL, row_sum TEXT NOT NULL);
"""


def _insert(con: sqlite3.Connection, table: str, values: tuple[object, ...], verb: str = "INSERT OR REPLACE") -> None:
    """One row with its checksum (values given their columns' types first, so the sum is of what is stored)."""
    row = typed(table, values)
    con.execute(f"{verb} INTO {table} VALUES ({', '.join('?' * (len(row) + 1))})", (*row, row_sum(table, row)))


def _add_row_sums(con: sqlite3.Connection) -> None:
    """Schema 1 -> 2: a ``row_sum`` column in every table, filled from the rows as they are."""
    with con:
        for table, columns in COLUMNS.items():
            if "row_sum" in [r[1] for r in con.execute(f"PRAGMA table_info({table})")]:
                continue
            con.execute(f"ALTER TABLE {table} ADD COLUMN row_sum TEXT NOT NULL DEFAULT ''")
            names = ", ".join(name for name, _ in columns)
            for rowid, *values in con.execute(f"SELECT rowid, {names} FROM {table}").fetchall():
                row = typed(table, values)
                con.execute(f"UPDATE {table} SET row_sum = ? WHERE rowid = ?", (row_sum(table, row), rowid))
        con.execute("DELETE FROM meta WHERE key = 'schema'")
        _insert(con, "meta", ("schema", str(SCHEMA_VERSION)))


class LibraryIndexError(FormatError):
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
                raise LibraryIndexError(
                    f"{self.path} is damaged ({'; '.join(damage)[:120]}); move it away "
                    "and run cycles again to rebuild it from the clip files' sources"
                )
            self.con.executescript(_SCHEMA)
            meta_rows = self.con.execute("SELECT * FROM meta").fetchall()
        except sqlite3.DatabaseError as exc:
            raise LibraryIndexError(f"{self.path} is not a library index ({exc})") from None
        meta = {str(row[0]): str(row[1]) for row in meta_rows}
        schema = meta.get("schema", str(SCHEMA_VERSION))
        if not schema.isdigit():
            raise LibraryIndexError(f"{self.path} has schema {schema[:20]!r}, not a version number")
        version = int(schema)
        if version > SCHEMA_VERSION:
            raise LibraryIndexError(f"{self.path} has schema {version}; this puppetphone reads up to {SCHEMA_VERSION}")
        if version >= 2 and (bad := [str(row[0])[:40] for row in meta_rows if not intact("meta", row)]):
            raise LibraryIndexError(
                f"{self.path}: its {', '.join(map(repr, bad))} setting is damaged (checksum "
                "mismatch); move the index away and run cycles again to rebuild it"
            )
        built = meta.get("options")
        if built is not None and built != options_key:
            raise LibraryIndexError(f"{self.libdir} was built with {built}; use the same options or another -o")
        if version < 2 and meta:
            _add_row_sums(self.con)
        with self.con:
            _insert(self.con, "meta", ("schema", str(SCHEMA_VERSION)), "INSERT OR IGNORE")
            _insert(self.con, "meta", ("options", options_key), "INSERT OR IGNORE")
        self.notices: list[str] = []  # one line per kind of damage found while reading (``cycles`` prints them)

    def close(self) -> None:
        """Close the connection (everything recorded is committed already)."""
        self.con.close()

    def known_hashes(self, failed: bool = True) -> set[str]:
        """Content hashes of every take done: in the index, with each clip file it names intact
        (without the takes that failed, unless ``failed``: ``cycles --retry-failed``).

        A take whose clip count, clip files or their SHA-256 no longer match (a file deleted or
        changed, a damaged row) is left out, so the batch does it again and rewrites its rows.
        """
        query = "SELECT * FROM takes" + ("" if failed else " WHERE outcome != 'failed'")
        try:
            take_rows = self.con.execute(query).fetchall()
            clip_rows = self.con.execute("SELECT * FROM clips").fetchall()
        except sqlite3.DatabaseError as exc:
            raise LibraryIndexError(f"{self.path} is not a readable library index ({exc})") from None
        takes = {str(row[0]): int(row[8]) for row in take_rows if intact("takes", row)}
        damaged = len(take_rows) - len(takes)
        found: dict[str, int] = {}
        for row in clip_rows:
            take, file, digest = str(row[1]), str(row[0]), str(row[16])
            if not intact("clips", row):
                damaged += 1
            elif take in takes and self._intact(file, digest):
                found[take] = found.get(take, 0) + 1
        if damaged:
            self._notice(f"{damaged} damaged row(s) in takes/clips (checksum mismatch): their takes are done again")
        return {h for h, n in takes.items() if found.get(h, 0) == n}

    def _notice(self, line: str) -> None:
        """Say a damage once, on the terminal and in :attr:`notices`."""
        if line not in self.notices:
            self.notices.append(line)
            print(f"cycles: {self.path}: {line}", file=sys.stderr)

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
        row = self.con.execute(
            "SELECT * FROM sources WHERE path = ? AND size = ? AND mtime_ns = ?", (path, size, mtime_ns)
        ).fetchone()
        if row is not None and not intact("sources", row):
            self._notice("a damaged row in sources (checksum mismatch): its file is read again")
            return None
        return None if row is None else str(row[3])

    def remember_source(self, path: str, size: int, mtime_ns: int, digest: str) -> None:
        """Note a source's hash (committed with the next take, or by :meth:`commit`)."""
        _insert(self.con, "sources", (path, size, mtime_ns, digest))

    def commit(self) -> None:
        """Commit pending source notes."""
        self.con.commit()

    def record(self, outcome: TakeOutcome, files: list[str], licence: str) -> None:
        """One take and its clips, in one transaction (``files`` already written, relative to the library)."""
        with self.con:
            self.con.execute("DELETE FROM clips WHERE take = ?", (outcome.digest,))
            _insert(
                self.con,
                "takes",
                (
                    outcome.digest,
                    outcome.source,
                    licence,
                    outcome.outcome,
                    outcome.reason,
                    outcome.frames,
                    outcome.fps,
                    outcome.dims,
                    len(outcome.clips),
                    outcome.seconds,
                ),
            )
            for clip, file in zip(outcome.clips, files, strict=True):
                _insert(
                    self.con,
                    "clips",
                    (
                        file,
                        outcome.digest,
                        clip.segment,
                        clip.start_frame,
                        clip.end_frame,
                        clip.start_s,
                        clip.end_s,
                        clip.kind,
                        clip.period,
                        clip.cycles,
                        clip.closure_error,
                        clip.spread,
                        clip.speed,
                        clip.dims,
                        outcome.source,
                        licence,
                        hashlib.sha256(clip.data).hexdigest(),
                    ),
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
            _checked_rows(con, "meta", "key", path)
            _checked_rows(con, "sources", "path", path)
            takes = [TakeEntry(**row) for row in _checked_rows(con, "takes", "source, hash", path)]
            clips = [
                ClipEntry(**row, path=libdir / str(row["file"]))
                for row in _checked_rows(con, "clips", "source, start_frame, file", path)
            ]
        finally:
            con.close()
    except sqlite3.DatabaseError as exc:
        raise LibraryIndexError(f"{path} is not a readable library index ({exc})") from None
    return takes, clips


def _checked_rows(con: sqlite3.Connection, table: str, order: str, path: Path) -> list[dict[str, Any]]:
    """Every row of ``table`` as a dict of its columns, each checked against its ``row_sum``
    (an index of schema 1 has none to check). Values are SQLite's, untyped until the entry classes read them.

    Raises:
        LibraryIndexError: a row whose values are not what was written.
    """
    cur = con.execute(f"SELECT * FROM {table} ORDER BY {order}")
    names = [d[0] for d in cur.description]
    summed = names[-1] == "row_sum"
    out = []
    for row in cur:
        if summed and not intact(table, row):
            raise LibraryIndexError(
                f"{path}: a row of {table} ({str(row[0])[:60]!r}) is damaged (checksum mismatch); "
                "run cycles again on the same sources to redo its take"
            )
        out.append(dict(zip(names[:-1] if summed else names, row[:-1] if summed else row, strict=True)))
    return out
