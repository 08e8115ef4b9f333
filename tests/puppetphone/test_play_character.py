"""``play --character FILE.glb``: the player's puppet is the character, and its recording replays
bit for bit after the file is gone (the set-up carries it)."""

from __future__ import annotations

import shutil
from dataclasses import asdict
from pathlib import Path

import numpy as np
import pytest

from engine.character.puppet import CharacterSkin
from engine.character.setup import character_setup
from engine.components import Puppet
from engine.statemachine import Brain
from input.hub import InputHub
from input.mouse import MouseSource
from input.mousebot import MouseBot
from input.recording import Recorder, RecordingHeader
from puppetphone.cli import main
from puppetphone.games import load_game, make_app


def _record(glb: Path, path: Path) -> list[str]:
    """Snowman with the character: grab it, walk it, lift it high and let go (it falls as a ragdoll)."""
    game = load_game("snowman")
    setup = {
        **game.prepare({**game.options, "field": str(path.with_suffix(".field.json"))}),
        "character": character_setup(str(glb)),
    }
    mouse = MouseSource()
    app = make_app("snowman", 5, InputHub([mouse]), setup)
    header = RecordingHeader(game="snowman", seed=5, dt=app.world.dt, sources=["mouse"], setup=setup)
    puppet = next(e for e, _ in app.world.query(Brain))
    assert app.world.has(puppet, CharacterSkin)
    assert app.world.get(puppet, Puppet).skeleton.offsets[0, 1] == pytest.approx(0.679, abs=1e-3)
    states = []
    with Recorder(path, header).attach(app):
        bot = MouseBot(app, mouse, game.camera())
        bot.wait(0.3)
        bot.press_on(puppet)
        bot.drag_path([np.array([0.0, 0.0, 1.5])], 1.0)  # walk
        for _ in range(6):  # lift well above standing height
            bot.wheel(1)
            bot.step(5)
        bot.wait(0.6)
        bot.release()
        for _ in range(150):
            bot.step()
            states.append(app.world.get(puppet, Brain).active)
    return states


def test_a_character_session_replays_after_its_file_is_moved_away(
    mocap_dir: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The set-up carries the file's bytes, not its path: the replay builds the same puppet without the file."""
    glb = tmp_path / "hero.glb"
    shutil.copy(mocap_dir / "CesiumMan.glb", glb)
    rec = tmp_path / "hero.rec"
    states = _record(glb, rec)
    assert "Ragdoll" in states  # dropped from high up, it fell as a ragdoll
    glb.rename(tmp_path / "elsewhere.glb")
    assert main(["replay", str(rec), "--verify", "--headless"]) == 0, capsys.readouterr().err


def test_a_fox_is_refused_in_one_line_before_the_game_starts(
    mocap_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["play", "snowman", "--headless", "--frames", "2", "--character", str(mocap_dir / "Fox.glb")]) == 2
    err = capsys.readouterr().err
    errors = [ln for ln in err.splitlines() if ln.startswith("error")]
    assert len(errors) == 1 and "--joint-map FILE" in errors[0] and "Traceback" not in err


def test_a_recorded_character_that_was_altered_is_one_line(
    tmp_path: Path, mocap_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A crafted header's character is checked like the file was: exit 2, one line."""
    import json
    import struct
    import zlib

    from input.recording import MAGIC

    value = character_setup(str(mocap_dir / "CesiumMan.glb"))
    head = asdict(RecordingHeader(game="snowman", seed=1, dt=1 / 60))
    head["setup"] = {"character": dict(value, sha256="0" * 64)}
    raw = json.dumps(head, sort_keys=True).encode()
    path = tmp_path / "c.rec"
    path.write_bytes(MAGIC + struct.pack("<II", len(raw), zlib.crc32(raw)) + raw + struct.pack("<II", 0, 0))
    assert main(["replay", str(path), "--headless", "--frames", "2"]) == 2
    err = capsys.readouterr().err
    assert "does not match its hash" in err and "Traceback" not in err
