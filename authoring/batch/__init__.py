"""Batch cycle extraction: a folder of mocap takes in, a library of loops and its index out.

:mod:`.worker` holds the task (one take → its loops, as bytes; the same on any
scheduler), :mod:`.runner` the scheduling (here, a process pool, a Dask cluster) and
the library folder, :mod:`.index` the SQLite index and the reader other commands use::

    takes, clips = read_index("lib/")
    walks = [c for c in clips if c.kind == "walk" and c.speed and 1.0 < c.speed < 1.5]
"""

from authoring.batch.index import INDEX_NAME, ClipEntry, LibraryIndex, LibraryIndexError, TakeEntry, read_index
from authoring.batch.worker import BatchOptions, ClipOut, TakeOutcome, TakeTask, process_take

__all__ = [
    "INDEX_NAME",
    "BatchOptions",
    "ClipEntry",
    "ClipOut",
    "LibraryIndex",
    "LibraryIndexError",
    "TakeEntry",
    "TakeOutcome",
    "TakeTask",
    "process_take",
    "read_index",
]
