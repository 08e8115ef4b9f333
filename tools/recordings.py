"""Regenerate the puppet-brain recordings in ``tests/data``: ``python -m tools.regen recordings``.

Each recording is a short scripted session of the sandbox puppet driven through the
real input path (see ``tests/engine/statemachine/puppet/sessions.py``); engine changes
that alter the simulation invalidate their state hashes, and this script is how they
are re-recorded. It prints each session's state sequence so a change in behaviour is
visible before the tests are run.
"""

from __future__ import annotations

import importlib.util
import sys

from tools import REPO

_SESSIONS = REPO / "tests" / "engine" / "statemachine" / "puppet" / "sessions.py"


def load_sessions():  # type: ignore[no-untyped-def]
    """The sessions module, loaded by path (tests are not an installed package)."""
    spec = importlib.util.spec_from_file_location("puppet_sessions", _SESSIONS)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


def main(argv: list[str]) -> int:
    """Record the named sessions (all by default)."""
    sessions = load_sessions()
    names = argv or list(sessions.SESSIONS)
    unknown = [n for n in names if n not in sessions.SESSIONS]
    if unknown:
        print(f"unknown session(s) {', '.join(unknown)}; sessions are {', '.join(sessions.SESSIONS)}", file=sys.stderr)
        return 2
    for name in names:
        session = sessions.SESSIONS[name]
        app = sessions.record(session)
        brain = app.world.get(sessions.puppet_of(app), sessions.Brain)
        steps = " -> ".join(f"{t.target}@{t.frame}" for t in brain.trace)
        print(f"{session.path.name}: {app.world.frame} frames; {steps}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
