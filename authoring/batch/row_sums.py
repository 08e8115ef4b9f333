"""A checksum in every row of the library index, because SQLite keeps none of the values it stores.

``PRAGMA quick_check`` finds a damaged page, not a changed value: a flipped bit in a period,
a source path or a take's outcome reads back as a valid, wrong row. So every row of every
table of ``index.sqlite`` (``meta``, ``takes``, ``clips``, ``sources``) carries ``row_sum``, a
BLAKE2b-64 of the table's name and the row's values, computed on the values written and
checked on every read. Values are first given the exact Python type of their column (a
``REAL`` column stores ``60`` as ``60.0``), so what is summed is what comes back.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Callable, Sequence
from typing import Any

__all__ = ["COLUMNS", "intact", "row_sum", "typed"]

_T = {"TEXT": str, "INTEGER": int, "REAL": float}

#: Every table's columns and their types, in order (``row_sum`` comes last in the file).
COLUMNS: dict[str, tuple[tuple[str, str], ...]] = {
    "meta": (("key", "TEXT"), ("value", "TEXT")),
    "takes": (
        ("hash", "TEXT"),
        ("source", "TEXT"),
        ("licence", "TEXT"),
        ("outcome", "TEXT"),
        ("reason", "TEXT"),
        ("frames", "INTEGER"),
        ("fps", "REAL"),
        ("dims", "INTEGER"),
        ("clips", "INTEGER"),
        ("seconds", "REAL"),
    ),
    "clips": (
        ("file", "TEXT"),
        ("take", "TEXT"),
        ("segment", "INTEGER"),
        ("start_frame", "INTEGER"),
        ("end_frame", "INTEGER"),
        ("start_s", "REAL"),
        ("end_s", "REAL"),
        ("kind", "TEXT"),
        ("period", "REAL"),
        ("cycles", "INTEGER"),
        ("closure_error", "REAL"),
        ("spread", "REAL"),
        ("speed", "REAL NULL"),
        ("dims", "INTEGER"),
        ("source", "TEXT"),
        ("licence", "TEXT"),
        ("sha256", "TEXT"),
    ),
    "sources": (("path", "TEXT"), ("size", "INTEGER"), ("mtime_ns", "INTEGER"), ("hash", "TEXT")),
}


def typed(table: str, values: Sequence[Any]) -> tuple[Any, ...]:
    """``values`` in the Python types their columns store (``None`` only where a column allows it)."""
    out = []
    for (_, kind), value in zip(COLUMNS[table], values, strict=True):
        cast: Callable[[Any], Any] = _T[kind.split()[0]]
        out.append(None if value is None and kind.endswith("NULL") else cast(value))
    return tuple(out)


def row_sum(table: str, values: Sequence[Any]) -> str:
    """The checksum of one row's (typed) values: 16 hex digits."""
    text = json.dumps([table, *values], ensure_ascii=False, allow_nan=True)  # floats as repr: exact
    return hashlib.blake2b(text.encode("utf-8", "surrogatepass"), digest_size=8).hexdigest()


def intact(table: str, row: Sequence[Any]) -> bool:
    """Whether a row read back (its values then ``row_sum``) is what was written."""
    *values, digest = row
    return len(values) == len(COLUMNS[table]) and row_sum(table, values) == digest
