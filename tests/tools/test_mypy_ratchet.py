"""The type-debt ratchet reads mypy's summary line."""

from __future__ import annotations

from tools.mypy_ratchet import error_count


def test_the_count_comes_from_the_summary_line() -> None:
    assert error_count("a.py:1: error: x  [arg-type]\nFound 117 errors in 46 files (checked 366 source files)\n") == 117
    assert error_count("Found 1 error in 1 file (checked 3 source files)\n") == 1
    assert error_count("Success: no issues found in 366 source files\n") == 0
