"""Every ``type: ignore`` in the runtime packages names its error code and says why.

mypy (configured in pyproject.toml, run by .ci/run) flags an ignore without a code and an
ignore that no longer silences anything; this test adds the third rule of the gate: the
reason, on the same line, after the bracket (``# type: ignore[arg-type]  # why``), so a
reader never has to guess whether a silenced error is a real bug.

There are none left (78 when the rule was set, most of them ``no-untyped-def`` on the tools'
functions moved out of the launcher); the test keeps it so.
"""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
RUNTIME = ("engine", "input", "authoring", "games", "puppetphone")
IGNORE = re.compile(r"#\s*type:\s*ignore(?P<codes>\[[^\]]*\])?(?P<rest>.*)$")


def unexplained_ignores(text: str) -> list[tuple[int, str]]:
    """The ``(line number, line)`` of each ignore without an error code or without a reason."""
    bad = []
    for n, line in enumerate(text.splitlines(), 1):
        m = IGNORE.search(line)
        if m and (not m.group("codes") or not re.match(r"\s*#\s*\S", m.group("rest"))):
            bad.append((n, line.strip()))
    return bad


def test_the_rule_sees_a_bare_ignore_and_accepts_a_reasoned_one() -> None:
    text = "a = f(x)  # type: ignore\nb = g(y)  # type: ignore[arg-type]\nc = h(z)  # type: ignore[arg-type]  # why\n"
    assert [n for n, _ in unexplained_ignores(text)] == [1, 2]


def test_every_runtime_ignore_has_a_code_and_a_reason() -> None:
    bad = [
        f"{path.relative_to(ROOT)}:{n}: {line}"
        for package in RUNTIME
        for path in sorted((ROOT / package).rglob("*.py"))
        for n, line in unexplained_ignores(path.read_text(encoding="utf-8"))
    ]
    assert not bad, f"{len(bad)} type: ignore without a code or a reason:\n" + "\n".join(bad)
