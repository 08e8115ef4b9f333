"""``puppetphone replay FILE --verify``: rebuilt from the header, every hash compared."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from engine import quat
from input.hub import InputHub
from input.recording import Recorder, RecordingHeader, read_recording
from input.sample import PoseSample
from input.source import PoseSource
from puppetphone.cli import main
from puppetphone.games import make_app

REPO = Path(__file__).resolve().parents[2]
# The snowman demo (4,666 steps, the longest replay) is replayed once per run, through this same
# command, by tests/games/snowman/test_demo.py, which also checks the world it ends in.
SNOWMAN_DEMO = REPO / "games" / "snowman" / "demo.rec"
SHIPPED = sorted(
    p for p in [*(REPO / "tests" / "data").glob("*.rec"), *(REPO / "games").glob("*/demo.rec")] if p != SNOWMAN_DEMO
)
#: Frames of a recording that another test already replays to its end (see :func:`verified_in_full_elsewhere`).
PREFIX = 60


def verified_in_full_elsewhere(path: Path) -> Path | None:
    """The test file that replays ``path`` to its last frame with every hash compared, or ``None``.

    The puppet sessions (``tests/data/puppet_<name>.rec``) are replayed by name in
    test_recorded_sessions.py, whose ``replay`` asserts every frame matched; the tasbada demo by
    tests/games/tasbada/test_demo_replay.py. A recording no other test names is replayed in full below."""
    if path.parent == REPO / "tests" / "data" and path.stem.startswith("puppet_"):
        by = REPO / "tests" / "engine" / "statemachine" / "puppet" / "test_recorded_sessions.py"
        named = f'"{path.stem.removeprefix("puppet_")}"'
    elif path == REPO / "games" / "tasbada" / "demo.rec":
        by, named = REPO / "tests" / "games" / "tasbada" / "test_demo_replay.py", '"demo.rec"'
    else:
        return None
    return by if named in by.read_text(encoding="utf-8") else None


class Fed(PoseSource):
    threaded = False


def record(path, steps=90):
    """A phone grabbing and swinging the sandbox puppet, recorded as ``play --record`` does."""
    src = Fed("phone")
    app = make_app("sandbox", 11, InputHub([src]))
    rec = Recorder(path, RecordingHeader("sandbox", 11, app.world.dt, ["phone"])).attach(app)
    for i in range(steps):
        q = quat.from_axis_angle([1, 0, 0], -0.4 + 0.01 * i)
        src.push(PoseSample(time=i / 60, source="osc:10.0.0.9", orientation=q, touch=i in range(2, 3) or i > 20))
        app.step()
    rec.close()


def test_verify_reports_all_hashes_match(tmp_path, capsys):
    path = tmp_path / "s.rec"
    record(path)
    assert main(["replay", str(path), "--verify", "--headless"]) == 0
    assert capsys.readouterr().out.strip() == "replayed 90 frames, all 90 state hashes match"


def test_first_differing_frame_is_named(tmp_path, capsys):
    path = tmp_path / "s.rec"
    record(path)
    data = bytearray(path.read_bytes())
    # Corrupt the stored hash of frame 40 and fix its checksum, as a diverging build would produce.
    import zlib

    from input.recording import MAGIC

    pos = len(MAGIC) + 8 + int.from_bytes(data[len(MAGIC) : len(MAGIC) + 4], "little")
    for _ in range(40):
        pos += 8 + int.from_bytes(data[pos : pos + 4], "little")
    n = int.from_bytes(data[pos : pos + 4], "little")
    data[pos + 8] ^= 0xFF
    data[pos + 4 : pos + 8] = zlib.crc32(bytes(data[pos + 8 : pos + 8 + n])).to_bytes(4, "little")
    path.write_bytes(bytes(data))
    assert main(["replay", str(path), "--verify", "--headless"]) == 1
    assert "differs at frame 40" in capsys.readouterr().out


def test_a_cut_recording_fails_unless_allowed(tmp_path, capsys):
    path = tmp_path / "s.rec"
    record(path)
    path.write_bytes(path.read_bytes()[:-10])
    assert main(["replay", str(path), "--verify", "--headless"]) == 1
    assert "cut inside the record of frame 89" in capsys.readouterr().err
    assert main(["replay", str(path), "--verify", "--headless", "--allow-truncated"]) == 0
    out = capsys.readouterr()
    assert "warning" in out.err and "89 complete frames" in out.err
    assert "replayed 89 frames, all 89 state hashes match" in out.out


def test_allow_truncated_does_not_accept_a_damaged_record(tmp_path, capsys):
    """``--allow-truncated`` forgives a file cut short (a session killed mid-write), never a record whose
    checksum fails: that file was changed after it was written.

    Shown to fail when ``cut_short`` is taken as "any incomplete recording" (``not rec.complete``)."""
    path = tmp_path / "s.rec"
    record(path)
    data = bytearray(path.read_bytes())
    data[-20] ^= 0x55  # the last record's payload: its checksum no longer matches
    path.write_bytes(bytes(data))
    assert main(["replay", str(path), "--verify", "--headless", "--allow-truncated"]) == 1
    out = capsys.readouterr()
    assert "error" in out.err and "damaged record at frame 89" in out.err and "warning" not in out.err


def test_plain_replay_also_fails_on_a_differing_hash(tmp_path, capsys):
    path = tmp_path / "s.rec"
    record(path)
    data = bytearray(path.read_bytes())
    data[-20] ^= 0x55  # the last record's payload: its checksum no longer matches
    path.write_bytes(bytes(data))
    assert main(["replay", str(path), "--headless"]) == 1
    assert "damaged record at frame 89" in capsys.readouterr().err


def test_a_device_or_pipe_is_refused(capsys):
    assert main(["replay", "/dev/zero", "--headless"]) == 2
    assert "not a regular file" in capsys.readouterr().err


@pytest.mark.parametrize("path", SHIPPED, ids=lambda p: str(p.relative_to(REPO)))
def test_every_shipped_recording_verifies_through_the_command(path):
    """As a user types it: a subprocess, the console script, the shipped file.

    What the command adds to a replay is the game rebuilt from the recording's header and the runner
    feeding it the recorded input; a game rebuilt differently already differs at its first state hash,
    and the runner's long run is the snowman demo's (4,666 steps through this command). So a recording
    that another test replays to its end is replayed here for its first ``PREFIX`` frames; any other,
    in full. Broken once by giving the command the wrong seed (``h.seed + 1``): every case fails at frame 0."""
    frames = ["--frames", str(PREFIX)] if verified_in_full_elsewhere(path) else []
    env = {**os.environ, "SDL_VIDEODRIVER": "dummy"}
    done = subprocess.run(
        [sys.executable, "-m", "puppetphone", "replay", str(path), "--verify", "--headless", *frames],
        capture_output=True,
        text=True,
        env=env,
        timeout=600,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    n = PREFIX if frames else len(read_recording(path))
    assert f"replayed {n} frames, all {n} state hashes match" in done.stdout, done.stdout


def test_the_recordings_replayed_in_part_here_are_replayed_in_full_elsewhere():
    """Every shipped puppet session and the tasbada demo is named by the test that replays it to its end
    (a new recording that none names is replayed in full by the command test above instead)."""
    elsewhere = {p.name for p in SHIPPED if verified_in_full_elsewhere(p)}
    assert {p.name for p in (REPO / "tests" / "data").glob("puppet_*.rec")} <= elsewhere
    assert "demo.rec" in elsewhere
    assert verified_in_full_elsewhere(REPO / "tests" / "data" / "puppet_not_recorded.rec") is None


def test_not_a_recording_is_a_clear_error(tmp_path, capsys):
    path = tmp_path / "x.rec"
    path.write_bytes(b"hello")
    assert main(["replay", str(path), "--verify"]) == 2
    assert "not a PuppetPhone recording" in capsys.readouterr().err


def test_a_divergence_names_the_component_type_that_differs_first(tmp_path):
    from engine.components import Transform
    from engine.statemachine import Brain
    from input.recording import read_recording
    from input.replay import verify

    path = tmp_path / "s.rec"
    record(path)

    def nudged(hub):  # the same session, with one puppet moved by a micrometre at step 40
        app = make_app("sandbox", 11, hub)

        def nudge(world):
            if world.frame == 40:
                puppet = next(e for e, _ in world.query(Brain))
                world.get(puppet, Transform).position[0] += 1e-6

        app.add_system("rules", nudge)
        return app

    check = verify(nudged, read_recording(path))
    assert check.first_mismatch == 40 and check.matched == 40
    assert check.differing[0] == "engine.components.Transform"
    assert "differs at frame 40 in engine.components.Transform" in check.message()
