"""Reset, save and restore of the snowman field: round trips, damaged saves, recorded commands."""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest

from engine.components import Transform
from engine.ragdoll.components import Prop
from games.snowman.components import Snowball, Snowman, SnowmanStats, Stacked
from games.snowman.field_save import FieldError, FieldSlot, restore, snapshot, start_snapshot
from games.snowman.rig import SnowmanShape
from games.snowman.rules import spawn_ball
from games.snowman.snow import SnowField
from input.hub import InputHub
from input.recording import Recorder, RecordingHeader, read_recording
from input.replay import verify
from input.sample import RESET, RESTORE, SAVE
from puppetphone.games import load_game, make_app


@pytest.fixture(autouse=True)
def field_file(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    path = tmp_path / "field.json"
    monkeypatch.setenv("SNOWMAN_FIELD", str(path))
    return path


def _live_app(hub: InputHub):  # type: ignore[no-untyped-def]
    """The snowman as ``play`` builds it: the game's prepare reads the field file first."""
    return make_app("snowman", 3, hub, load_game("snowman").prepare({"field": ""}))


def _built_field(hub: InputHub | None = None):  # type: ignore[no-untyped-def]
    """A field with a rolled track, a stack of two balls, a loose ball and a snowman."""
    from games.snowman.alive import bring_to_life

    app = _live_app(hub or InputHub())
    world = app.world
    world.resource(SnowField).roll(np.array([-2.0, 0.2, 0.0]), np.array([1.0, 0.2, 0.5]), 0.2)
    bottom = spawn_ball(world, np.array([2.0, 0.0, 1.0]), 0.4)
    top = spawn_ball(world, np.array([2.0, 0.0, 1.0]), 0.18)
    spawn_ball(world, np.array([-1.0, 0.0, -2.0]), 0.25)
    world.flush()
    world.add(top, Stacked(on=bottom))
    world.get(top, Prop).carried = True
    bring_to_life(world, SnowmanShape(0.4, 0.3, 0.2), np.array([-3.0, 0.0, 2.0]), 0.5, 1)
    world.resource(SnowmanStats).built = 1
    app.run_steps(30)
    return app


def _same(a: dict, b: dict) -> None:
    assert a["stats"] == b["stats"] and a["snow"] == b["snow"]
    assert [(x["radius"], x["on"]) for x in a["balls"]] == [(x["radius"], x["on"]) for x in b["balls"]]
    assert np.allclose([x["position"] for x in a["balls"]], [x["position"] for x in b["balls"]], atol=1e-9)
    assert [(s["number"], s["bottom"], s["middle"], s["head"]) for s in a["snowmen"]] == [
        (s["number"], s["bottom"], s["middle"], s["head"]) for s in b["snowmen"]
    ]
    assert np.allclose([s["position"] for s in a["snowmen"]], [s["position"] for s in b["snowmen"]], atol=1e-9)


def test_snapshot_survives_json_and_restores_the_same_field() -> None:
    app = _built_field()
    saved = json.loads(json.dumps(snapshot(app.world)))
    assert len(saved["balls"]) == 3 and sum(b["on"] is not None for b in saved["balls"]) == 1
    assert len(saved["snowmen"]) == 1 and len(saved["puppets"]) == 1
    restore(app.world, {**saved, "balls": [], "snowmen": [], "snow": None})
    app.world.flush()
    assert not app.world.query(Snowball) and not app.world.query(Snowman)
    restore(app.world, saved)
    app.world.flush()
    _same(snapshot(app.world), saved)
    app.run_steps(30)  # the restored stack stays packed, the snowman stands
    world = app.world
    stacked = [e for e, _ in world.query(Stacked)]
    assert len(stacked) == 1 and world.get(stacked[0], Prop).carried
    assert len(world.query(Snowman)) == 1


def test_a_damaged_save_changes_nothing() -> None:
    app = _built_field()
    before = snapshot(app.world)
    bad = json.loads(json.dumps(before))
    bad["balls"][0]["position"] = [0.0, float("nan"), 0.0]
    with pytest.raises(FieldError, match="finite"):
        restore(app.world, bad)
    truncated = json.loads(json.dumps(before))
    truncated["snow"]["zlib_f8"] = truncated["snow"]["zlib_f8"][:40]
    with pytest.raises(FieldError, match="snow grid"):
        restore(app.world, truncated)
    mistyped = json.loads(json.dumps(before))
    mistyped["snowmen"][0]["bottom"] = "big"
    with pytest.raises(FieldError, match="snowman bottom"):
        restore(app.world, mistyped)
    app.world.flush()
    _same(snapshot(app.world), before)


def test_keys_save_reset_and_restore(tmp_path: Path, field_file: Path) -> None:
    hub = InputHub()
    app = _built_field(hub)
    hub.command(SAVE)
    app.run_steps(2)
    saved = json.loads(field_file.read_text())
    assert len(saved["balls"]) == 3 and not list(tmp_path.glob(".field.json.*.tmp"))
    hub.command(RESET)
    app.run_steps(2)
    assert not app.world.query(Snowball) and app.world.resource(SnowmanStats).built == 0
    assert float(app.world.resource(SnowField).depth.min()) == app.world.resource(SnowField).initial_depth
    hub.command(RESTORE)
    app.run_steps(2)
    assert len(app.world.query(Snowball)) == 3 and len(app.world.query(Snowman)) == 1
    with pytest.raises(ValueError, match="unknown command"):
        hub.command("explode")


def test_a_recorded_session_restoring_the_field_on_disk_replays_without_the_file(
    tmp_path: Path, field_file: Path
) -> None:
    field_file.write_text(json.dumps(snapshot(_built_field().world)))
    hub = InputHub()
    setup = load_game("snowman").prepare({"field": ""})
    app = make_app("snowman", 3, hub, setup)
    header = RecordingHeader(game="snowman", seed=3, dt=app.world.dt, setup=setup)
    rec_path = tmp_path / "session.rec"
    recorder = Recorder(rec_path, header).attach(app)
    app.run_steps(5)
    for command in (RESTORE, RESET, RESTORE):
        hub.command(command)
        app.run_steps(20)
    assert len(app.world.query(Snowball)) == 3
    recorder.close()
    field_file.unlink()  # the replay must not need it: the recording carries the field
    rec = read_recording(rec_path)
    assert rec.header.setup["field"] is not None
    replayed = load_game("snowman").replay_setup(rec.header.setup)
    seen = []
    result = verify(
        lambda h: make_app("snowman", 3, h, replayed),
        rec,
        on_step=lambda a, i: seen.append(len(a.world.query(Snowball))),
    )
    assert result.ok, result.message()
    assert seen[-1] == 3 and 0 in seen and not field_file.exists()  # restored, reset, restored; nothing written


def test_a_corrupt_save_file_is_set_aside_with_a_message(field_file: Path, capsys: pytest.CaptureFixture[str]) -> None:
    cut = json.dumps(start_snapshot())[:40]  # a field this program wrote, cut short
    field_file.write_text(cut)
    app = _live_app(InputHub())
    assert app.world.resource(FieldSlot).saved is None
    assert Path(str(field_file) + ".bad").read_text() == cut and not field_file.exists()
    assert "set aside" in capsys.readouterr().err
    app.run_steps(3)
    assert app.world.query(Transform)


def test_each_command_tells_the_player_on_screen_without_touching_the_hash() -> None:
    from engine.hashing import state_hash
    from games.common import Notice

    hub = InputHub()
    app = make_app("snowman", 3, hub)
    app.run_steps(3)
    assert app.world.try_resource(Notice) is None
    for kind, text in [
        (RESTORE, "nothing saved to restore (F5 saves the field)"),
        (SAVE, "field saved"),
        (RESTORE, "field restored"),
        (RESET, "new field"),
    ]:
        hub.command(kind)
        app.step()
        notice = app.world.resource(Notice)
        assert (notice.text, notice.frame) == (text, app.world.frame - 1)
    before = state_hash(app.world)
    app.world.insert_resource(Notice("something else", 0))
    assert state_hash(app.world) == before  # display only: a replay verifies with or without it


def _edited(before: dict, edit) -> dict:  # type: ignore[no-untyped-def]
    snap = json.loads(json.dumps(before))
    edit(snap)
    return snap


def _zlib_bomb(snap: dict) -> None:
    import base64
    import zlib

    snap["snow"]["zlib_f8"] = base64.b64encode(zlib.compress(bytes(64 << 20), 9)).decode()


@pytest.mark.parametrize(
    "edit,says",
    [
        (lambda s: s["snowmen"][0].pop("heading"), "snowman heading"),  # used to raise after the field was cleared
        (lambda s: s["snowmen"][0].update(heading=float("nan")), "snowman heading"),
        (lambda s: s["puppets"][0].update(heading=float("inf")), "puppet heading"),
        (lambda s: s["balls"][0].pop("snow"), "ball snow"),
        (lambda s: s["balls"][0].update(position=[1e308, 0.0, 0.0]), "within"),
        (lambda s: s["balls"][0].update(on=0), "ring"),
        (lambda s: s["balls"].extend([dict(s["balls"][0], on=None)] * 1000), "at most"),
        (lambda s: s["snowmen"][0].update(number=True), "number"),
        (lambda s: s.update(stats=[]), "stats"),
        (_zlib_bomb, "snow grid"),
    ],
)
def test_a_bad_field_is_refused_whole_before_anything_changes(edit, says) -> None:  # type: ignore[no-untyped-def]
    app = _built_field()
    before = snapshot(app.world)
    with pytest.raises(FieldError, match=says):
        restore(app.world, _edited(before, edit))
    app.world.flush()
    _same(snapshot(app.world), before)
    app.run_steps(2)


def test_a_deeply_nested_save_file_is_set_aside(field_file: Path, capsys: pytest.CaptureFixture[str]) -> None:
    field_file.write_text('{"version": 1, "balls": ' + "[" * 100_000 + "]" * 100_000 + "}")
    app = _live_app(InputHub())
    assert app.world.resource(FieldSlot).saved is None and not field_file.exists()
    assert "nested too deeply" in capsys.readouterr().err
    app.run_steps(2)


def test_a_bad_file_is_set_aside_beside_an_existing_bad_without_replacing_it(
    field_file: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    snap = _edited(start_snapshot(), lambda s: s["puppets"][0].update(heading=float("nan")))
    field_file.write_text(json.dumps(snap))
    blocker = Path(str(field_file) + ".bad")
    blocker.mkdir()
    (blocker / "keep").write_text("x")  # a folder where the .bad file would go
    app = _live_app(InputHub())
    assert app.world.resource(FieldSlot).saved is None
    assert (blocker / "keep").read_text() == "x" and json.loads(Path(f"{field_file}.1.bad").read_text()) is not None
    assert "set aside" in capsys.readouterr().err
    app.run_steps(3)


@pytest.mark.parametrize(
    "make",
    [
        lambda p: (p.mkdir(), (p / "notes.txt").write_text("mine")),  # a user's folder
        lambda p: p.write_text("my shopping list\n"),  # a user's text file
        lambda p: p.write_text("[" * 100_000),  # not JSON a field ever was
    ],
)
def test_a_field_path_holding_something_else_is_refused_and_left_untouched(field_file: Path, make) -> None:  # type: ignore[no-untyped-def]
    from games.base import GameOptionError

    make(field_file)
    before = sorted((str(p), p.read_bytes()) for p in field_file.parent.rglob("*") if p.is_file())
    with pytest.raises(GameOptionError, match="not a field this program saved"):
        load_game("snowman").prepare({"field": str(field_file)})
    assert sorted((str(p), p.read_bytes()) for p in field_file.parent.rglob("*") if p.is_file()) == before


def test_a_pipe_as_field_is_refused_and_never_renamed(tmp_path: Path) -> None:
    """A pipe stands for any special file (a device: run as root, the old code renamed /dev/null)."""
    import stat

    from games.base import GameOptionError

    pipe = tmp_path / "pipe"
    os.mkfifo(pipe)
    with pytest.raises(GameOptionError, match="not a field this program saved"):
        load_game("snowman").prepare({"field": str(pipe)})
    assert stat.S_ISFIFO(pipe.lstat().st_mode) and not Path(f"{pipe}.bad").exists()


def test_a_failed_f5_says_so_keeps_playing_and_keeps_the_field(
    field_file: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from games.common import Notice

    hub = InputHub()
    app = _live_app(hub)
    field_file.mkdir()  # a folder appears in the way after the start
    hub.command(SAVE)
    app.step()
    assert app.world.resource(Notice).text.startswith("field NOT saved")
    out = capsys.readouterr().out
    assert "cannot save" in out and "Traceback" not in out and len(out.strip().splitlines()) == 1
    assert app.world.resource(FieldSlot).saved is not None and field_file.is_dir()
    field_file.rmdir()
    field_file.write_text("someone else's file")  # nor is a foreign file replaced by F5
    hub.command(SAVE)
    app.step()
    assert field_file.read_text() == "someone else's file"
    hub.command(RESTORE)
    app.run_steps(3)
    assert app.world.resource(Notice).text == "field restored"


def test_a_replay_whose_header_carries_a_bad_field_plays_on(tmp_path: Path) -> None:
    bad = _edited(start_snapshot(), lambda s: s["puppets"][0].update(heading=float("nan")))
    hub = InputHub()
    app = make_app("snowman", 3, hub)
    rec_path = tmp_path / "s.rec"
    recorder = Recorder(
        rec_path, RecordingHeader(game="snowman", seed=3, dt=app.world.dt, setup={"field": bad})
    ).attach(app)
    hub.command(RESTORE)
    app.run_steps(5)
    recorder.close()
    rec = read_recording(rec_path)
    replayed = load_game("snowman").replay_setup(rec.header.setup)
    assert replayed["field"] is None
    result = verify(lambda h: make_app("snowman", 3, h, replayed), rec)
    assert result.matched == 5


def test_stale_temporaries_of_killed_saves_are_removed_at_the_next_save(tmp_path: Path, field_file: Path) -> None:
    import os

    stale = tmp_path / ".field.json.k1ll3d.tmp"
    stale.write_text("half a save")
    os.utime(stale, (1.0, 1.0))
    fresh = tmp_path / ".field.json.wr1t1ng.tmp"  # a save in progress elsewhere: left alone
    fresh.write_text("")
    hub = InputHub()
    app = _live_app(hub)
    hub.command(SAVE)
    app.run_steps(2)
    assert field_file.exists() and not stale.exists() and fresh.exists()
