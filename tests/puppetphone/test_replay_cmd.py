"""``puppetphone replay FILE --verify``: rebuilt from the header, every hash compared."""

from __future__ import annotations

import sys
import types

import numpy as np
import pytest

from engine import quat
from engine.app import App
from engine.components import Grabbable, Stick, Transform
from input.hub import InputHub
from input.plugin import install_input
from input.recording import Recorder, RecordingHeader
from input.sample import PoseSample
from input.source import PoseSource
from puppetphone.cli import main


def make_app(game: str, seed: int, hub: InputHub) -> App:
    """Stand-in for puppetphone.games.make_app: a field with one grabbable thing."""
    assert game == "sandbox"
    app = App(seed=seed)
    install_input(app, hub)
    app.world.spawn(Transform(position=np.array([0.0, 0.95, 0.0])), Grabbable(0.6))

    def carry(world) -> None:
        for _, stick in world.query(Stick):
            if stick.grabbed is not None:
                world.get(stick.grabbed, Transform).position = stick.tip + world.rng.normal(0, 1e-3, 3)

    app.add_system("rules", carry)
    return app


@pytest.fixture
def games(monkeypatch):
    """The command is tested against ``make_app``'s signature with the stand-in above, so the
    test does not depend on which games are ready (the end-to-end test runs the real ones)."""
    stand_in = types.SimpleNamespace(make_app=make_app)
    monkeypatch.setitem(sys.modules, "puppetphone.games", stand_in)
    return stand_in


class Fed(PoseSource):
    threaded = False


def record(path, games, steps=90):
    src = Fed("phone")
    app = games.make_app("sandbox", 11, InputHub([src]))
    rec = Recorder(path, RecordingHeader("sandbox", 11, app.world.dt, ["phone"])).attach(app)
    for i in range(steps):
        q = quat.from_axis_angle([1, 0, 0], -0.4 + 0.01 * i)
        src.push(PoseSample(time=i / 60, source="osc:10.0.0.9", orientation=q, touch=i in range(2, 3) or i > 20))
        app.step()
    rec.close()


def test_verify_reports_all_hashes_match(tmp_path, games, capsys):
    path = tmp_path / "s.rec"
    record(path, games)
    assert main(["replay", str(path), "--verify", "--headless"]) == 0
    assert capsys.readouterr().out.strip() == "replayed 90 frames, all 90 state hashes match"


def test_first_differing_frame_is_named(tmp_path, games, capsys):
    path = tmp_path / "s.rec"
    record(path, games)
    data = bytearray(path.read_bytes())
    # Corrupt the stored hash of frame 40 and fix its checksum, as a diverging build would produce.
    import zlib

    from input.recording import MAGIC

    pos = len(MAGIC) + 8 + int.from_bytes(data[len(MAGIC):len(MAGIC) + 4], "little")
    for _ in range(40):
        pos += 8 + int.from_bytes(data[pos:pos + 4], "little")
    n = int.from_bytes(data[pos:pos + 4], "little")
    data[pos + 8] ^= 0xFF
    data[pos + 4:pos + 8] = zlib.crc32(bytes(data[pos + 8:pos + 8 + n])).to_bytes(4, "little")
    path.write_bytes(bytes(data))
    assert main(["replay", str(path), "--verify", "--headless"]) == 1
    assert "differs at frame 40" in capsys.readouterr().out


def test_truncated_recording_replays_with_a_warning(tmp_path, games, capsys):
    path = tmp_path / "s.rec"
    record(path, games)
    path.write_bytes(path.read_bytes()[:-10])
    assert main(["replay", str(path), "--verify", "--headless"]) == 0
    out = capsys.readouterr()
    assert "warning" in out.err and "89 complete frames" in out.err
    assert "replayed 89 frames, all 89 state hashes match" in out.out


def test_not_a_recording_is_a_clear_error(tmp_path, capsys):
    path = tmp_path / "x.rec"
    path.write_bytes(b"hello")
    assert main(["replay", str(path), "--verify"]) == 2
    assert "not a PuppetPhone recording" in capsys.readouterr().err
