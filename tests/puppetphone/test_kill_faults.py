"""``kill -9`` at random points of every save a person waits on: nothing saved earlier is lost.

Each test runs the product's own save path in a child process that saves over and over,
each time something different (``clips add`` of two walks in turn through the command's own
``main``, F5 in a live snowman game, Ctrl+S in a live ``author edit`` session after an edit,
a ``cycles`` batch), kills it with SIGKILL at a few seeded points (after a counted number of
saves, some way into the next), and checks that
what was saved before the kill is still there and opens: the library loads its walk (one
of the two), the field loads, the edited clip opens with its session file, the index reads
and every clip file it names has its recorded SHA-256. A handful of kill points each keeps
this fast; ``pytest -m fuzz`` runs a longer campaign (``FUZZ_CASES`` kill points, ``FUZZ_SEED``).
"""

from __future__ import annotations

import hashlib
import os
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import fuzz_cases

KILLS = 3


def _kill_points(n: int = KILLS, seed: int = 30, longest: float = 0.6) -> list[float]:
    return [float(x) for x in np.random.default_rng(seed).uniform(0.0, longest, n)]


SavePoint = tuple[int, float]


def _save_points(n: int = KILLS, seed: int = 30) -> list[SavePoint]:
    """Where to kill a saver: after how many more saves, then how far into the next one.

    Counted saves, not seconds, keep the kills apart on a loaded machine: the saves counted differ
    between kill points (1, 2, … in a seeded order), so the file on disk at each kill differs too;
    the seconds only place the kill inside the save under way (a save takes a few ms to ~0.1 s).
    """
    rng = np.random.default_rng(seed)
    counts = rng.permutation(np.arange(1, n + 1)) if n <= 8 else rng.integers(1, 9, n)
    return [(int(c), float(d)) for c, d in zip(counts, rng.uniform(0.0, 0.1, n), strict=True)]


def _kill_after(argv: list[str], point: SavePoint, env: dict[str, str] | None = None) -> None:
    """Start a saver, wait for its first save ("go") and ``point[0]`` more ("s" each), then ``point[1]``
    seconds into the next save, SIGKILL it."""
    saves, delay = point
    with subprocess.Popen(
        [sys.executable, "-c", *argv],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env={**os.environ, "SDL_VIDEODRIVER": "dummy", **(env or {})},
    ) as proc:
        assert proc.stdout is not None and proc.stderr is not None
        lines = iter(proc.stdout)
        for line in lines:  # the command's own lines, then "go"
            if line == b"go\n":
                break
        else:
            pytest.fail(f"the saver ended before its first save: {proc.stderr.read().decode()[-2000:]}")
        counted = 0
        while counted < saves:  # a save's own lines (``clips add`` prints what it added), then "s"
            line = next(lines, None)
            if line is None:
                pytest.fail(f"the saver stopped saving: {proc.stderr.read().decode()[-2000:]}")
            counted += line == b"s\n"
        time.sleep(delay)
        proc.send_signal(signal.SIGKILL)
        proc.wait(30)


CLIPS_ADD = """
import sys
from puppetphone.cli import main
library, a, b = sys.argv[1:4]
assert main(["clips", "add", a, "--role", "walk", "--clips", library]) == 0
print("go", flush=True)
for i in range(10**6):
    assert main(["clips", "add", (b, a)[i % 2], "--role", "walk", "--clips", library]) == 0
    print("s", flush=True)
"""


def _campaign() -> tuple[list[SavePoint], list[float]]:
    """The kill points (for the savers, for the batch): :data:`KILLS` in every run, ``FUZZ_CASES``
    under ``-m fuzz``."""
    cases, seed = fuzz_cases(KILLS)
    return _save_points(cases, 30 + seed), _kill_points(cases, 30 + seed)


def _clips_add(tmp_path: Path, points: list[SavePoint]) -> None:
    from engine.clipfile import save_clip
    from engine.cliplib.library import ClipLibrary, clip_digest
    from engine.clips import default_clips

    walk = default_clips()["walk"]
    a, b = tmp_path / "walk_a.ppclip", tmp_path / "walk_b.ppclip"
    save_clip(walk, a)
    save_clip(walk.resampled(55.0), b)
    library = tmp_path / "lib"
    added: set[str] = set()
    for point in points:
        _kill_after([CLIPS_ADD, str(library), str(a), str(b)], point)
        lib = ClipLibrary(library)
        added.add(clip_digest(lib.load()["walk"]))  # it loads: the old walk or the new one, never none
        assert lib.entries()["walk"].sha256 == clip_digest(lib.load()["walk"])
    assert 1 <= len(added) <= 2
    listed = subprocess.run(
        [sys.executable, "-m", "puppetphone", "clips", "list", "--clips", str(library)],
        capture_output=True,
        text=True,
        check=False,
        timeout=120,
    )
    assert listed.returncode == 0 and "walk" in listed.stdout, listed.stderr


def test_kill_9_during_clips_add_leaves_a_library_that_loads(tmp_path: Path) -> None:
    _clips_add(tmp_path, _save_points())


SNOWMAN_F5 = """
import sys
import numpy as np
from games.snowman.snow import SnowField
from input.hub import InputHub
from input.sample import SAVE
from puppetphone.games import load_game, make_app
hub = InputHub()
app = make_app("snowman", 3, hub, load_game("snowman").prepare({"field": sys.argv[1]}))
hub.command(SAVE)
app.step()
print("go", flush=True)
for i in range(10**6):
    x = -3.0 + 0.01 * (i % 600)  # the field changes between saves: a ball rolls a new track
    app.world.resource(SnowField).roll(np.array([x, 0.2, 0.0]), np.array([x + 0.05, 0.2, 0.0]), 0.2)
    hub.command(SAVE)
    app.step()
    print("s", flush=True)
"""


def _snowman_f5(tmp_path: Path, points: list[SavePoint]) -> None:
    from games.snowman.field_save import load_field
    from puppetphone.games import load_game

    field = tmp_path / "field.json"
    seen: set[str] = set()
    for point in points:
        _kill_after([SNOWMAN_F5, str(field)], point)
        assert load_field(field) is not None  # whole: the field before the kill or after it
        seen.add(hashlib.sha256(field.read_bytes()).hexdigest())
        assert load_game("snowman").prepare({"field": str(field)})["field"] is not None
        assert not list(tmp_path.glob("*.bad"))
    assert len(seen) > 1  # the kills did land between different saves


def test_kill_9_during_snowman_f5_leaves_the_field_that_loads(tmp_path: Path) -> None:
    _snowman_f5(tmp_path, _save_points())


AUTHOR_SAVE = """
import sys
from pathlib import Path
import numpy as np
from authoring.edit_tool import TOOL
from authoring.session import Session
from input.hub import InputHub
act = Session(TOOL.open({"clip": "walk", "output": Path(sys.argv[1])}, (160, 90)).simulation, InputHub())
def ctrl_s():
    act.hub.tool("key", "s", True, False)
    act.step()
    assert act.simulation.edit.message.startswith("saved"), act.simulation.edit.message
ctrl_s()
print("go", flush=True)
for i in range(10**6):
    session = act.simulation.edit.session  # what a drag of a control point does on release, a little each time
    session.move_control_point(act.simulation.edit.item, i % 4, np.array([0.0, 0.004 * (-1) ** i, 0.0]))
    ctrl_s()
    print("s", flush=True)
"""


def _author_edit(tmp_path: Path, points: list[SavePoint]) -> None:
    from authoring.mocurves import load_session
    from engine.cliplib.library import clip_digest

    out = tmp_path / "walk_edited.ppclip"
    seen: set[str] = set()
    for point in points:
        _kill_after([AUTHOR_SAVE, str(out)], point)
        session = load_session(out)  # the clip and its session file open together
        seen.add(clip_digest(session.clip))
    assert len(seen) > 1  # the kills did land between different saves
    again = subprocess.run(
        [sys.executable, "-m", "puppetphone", "author", "edit", str(out), "--headless", "--frames", "1"],
        capture_output=True,
        text=True,
        check=False,
        timeout=120,
        env={**os.environ, "SDL_VIDEODRIVER": "dummy"},
    )
    assert again.returncode == 0, again.stderr


def test_kill_9_during_author_edit_save_leaves_a_clip_that_opens(tmp_path: Path) -> None:
    _author_edit(tmp_path, _save_points())


def _done_takes(lib: Path) -> set[str]:
    """The takes of the index whose every clip file is there with its recorded SHA-256."""
    from authoring.batch.index import read_index

    takes, clips = read_index(lib)
    for clip in clips:
        assert hashlib.sha256(clip.path.read_bytes()).hexdigest() == clip.sha256, clip.file
    return {t.hash for t in takes}


def _cycles(tmp_path: Path, points: list[float], count: int) -> None:
    from puppetphone.bench.cycles_batch import write_takes

    write_takes(tmp_path / "takes", count=count)
    lib = tmp_path / "lib"
    argv = [
        sys.executable,
        "-m",
        "puppetphone",
        "cycles",
        str(tmp_path / "takes"),
        "-o",
        str(lib),
        "--jobs",
        "1",
        "--no-progress",
    ]
    done: set[str] = set()
    for delay in points:
        if len(done) == count:  # the kills came too late to stop the last runs: nothing left to cut
            break
        with subprocess.Popen(
            argv, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True
        ) as proc:
            deadline = time.monotonic() + 120  # a deadline for the test, not a measured time
            while proc.poll() is None and time.monotonic() < deadline:  # wait for this run's first new take
                try:
                    con = sqlite3.connect(f"file:{lib / 'index.sqlite'}?mode=ro", uri=True)
                    if con.execute("SELECT COUNT(*) FROM takes").fetchone()[0] > len(done):
                        con.close()
                        break
                    con.close()
                except sqlite3.Error:
                    pass
                time.sleep(0.05)
            time.sleep(delay)
            try:
                os.killpg(proc.pid, signal.SIGKILL)  # the main process and its workers
            except ProcessLookupError:
                pass  # this run finished first: what it did is checked the same way
            proc.wait(30)
        now = _done_takes(lib)
        assert done <= now, f"takes lost by the kill: {sorted(done - now)}"
        done = now
    finished = subprocess.run(argv, capture_output=True, text=True, check=False, timeout=600)
    assert finished.returncode == 0, finished.stderr
    assert len(_done_takes(lib)) == count and done <= _done_takes(lib)


def test_kill_9_during_a_cycles_batch_keeps_every_take_done_before(tmp_path: Path) -> None:
    _cycles(tmp_path, _kill_points(3, longest=1.0), count=8)


@pytest.mark.fuzz
@pytest.mark.parametrize("save", ["clips add", "snowman F5", "author edit", "cycles"])
def test_fuzz_kill_9_campaign(tmp_path: Path, save: str) -> None:
    """The long campaign: ``FUZZ_CASES`` kill points for each save."""
    saves, delays = _campaign()
    if save == "clips add":
        _clips_add(tmp_path, saves)
    elif save == "snowman F5":
        _snowman_f5(tmp_path, saves)
    elif save == "author edit":
        _author_edit(tmp_path, saves)
    else:
        _cycles(tmp_path, delays, count=max(8, 3 * len(delays)))


def test_kill_9_during_record_leaves_every_frame_before_it_replaying(tmp_path: Path) -> None:
    """A growing ``--record`` is append-only (see input/recording.py for why): a kill keeps every complete
    record, and the replay says the file was cut instead of calling it complete."""
    from input.recording import read_recording

    env = {**os.environ, "SDL_VIDEODRIVER": "dummy"}
    rec = tmp_path / "s.rec"
    for delay in _kill_points(1, longest=0.5):  # one: every cut position is read in tests/input/test_recording.py
        with subprocess.Popen(
            [
                sys.executable,
                "-m",
                "puppetphone",
                "play",
                "sandbox",
                "--headless",
                "--frames",
                "1000000",
                "--record",
                str(rec),
            ],
            env=env,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        ) as proc:
            deadline = time.monotonic() + 120  # a deadline for the test, not a measured time
            while not (rec.exists() and rec.stat().st_size > 2000):  # past its header and a few records
                assert proc.poll() is None and time.monotonic() < deadline
                time.sleep(0.05)
            time.sleep(delay)
            proc.send_signal(signal.SIGKILL)
            proc.wait(30)
        cut = read_recording(rec)
        assert not cut.complete and cut.cut and len(cut) > 0
        check = subprocess.run(
            [sys.executable, "-m", "puppetphone", "replay", str(rec), "--verify", "--headless", "--allow-truncated"],
            env=env,
            capture_output=True,
            text=True,
            check=False,
            timeout=300,
        )
        assert check.returncode == 0, check.stderr
        assert "ended without its closing record" in check.stderr or "cut inside" in check.stderr
        assert f"all {len(cut)} state hashes match" in check.stdout
