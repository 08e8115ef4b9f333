"""The one base class of every reader's error.

Each format (clips, recordings, glTF, BVH, saves, wire messages…) validates at its own
boundary and raises its own error class, which names the format in the message. They all
derive from :class:`FormatError`, so a caller that only needs to know "this input is bad"
(the command line, a file browser, a fuzz test) catches one type; ``ValueError`` stays a
base too, so code that caught the old classes as ``ValueError`` keeps working.
"""

from __future__ import annotations

__all__ = ["FormatError"]


class FormatError(ValueError):
    """Input that is not what its format says: truncated, corrupt, out of range or oversized."""
