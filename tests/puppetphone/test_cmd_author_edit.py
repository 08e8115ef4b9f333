"""``author edit`` headless: opens a default clip or a saved session, screenshots, exports."""

from __future__ import annotations

import argparse

import pytest

from authoring.mocurves import EditSession, save_session
from engine.clips import default_clips
from puppetphone.cmd_author import configure_edit
from puppetphone.cmd_author import run as run_author


def parse(*argv: str) -> argparse.Namespace:
    p = argparse.ArgumentParser()
    configure_edit(p)
    p.set_defaults(scene="edit")
    return p.parse_args(list(argv))


def run_edit(args: argparse.Namespace) -> int:
    return run_author(args)


def build_edit(spec, size, output, *, record=None):
    """A live edit session as ``author edit`` opens it (the tool's simulation in the one session class)."""
    from authoring.edit_tool import TOOL
    from authoring.session import Session
    from input.hub import InputHub

    opened = TOOL.open({"clip": spec, "output": output}, size)
    session = Session(opened.simulation, InputHub())
    if record is not None:
        session.record(record, TOOL.name, 0, opened.setup, "mouse")
    return session


def test_headless_run_screenshots_and_exports(tmp_path):
    from engine.render import egl_available

    if (reason := egl_available()) is not None:
        pytest.skip(f"no headless GL: {reason}")
    session = EditSession(default_clips()["walk"])
    session.retime("l_foot", {10: 0.2})
    saved = save_session(session, tmp_path / "walk.ppclip")
    shot, bvh = tmp_path / "shot.png", tmp_path / "out.bvh"
    args = parse(
        str(saved), "--headless", "--frames", "2", "--size", "320x180", "--screenshot", str(shot), "--export", str(bvh)
    )
    assert run_edit(args) == 0
    assert shot.stat().st_size > 1000 and bvh.read_text().startswith("HIERARCHY")


def test_unknown_clip_is_a_clear_error(capsys):
    assert run_edit(parse("no_such_clip", "--headless", "--frames", "1")) == 2
    assert "neither a .ppclip file nor a default clip" in capsys.readouterr().err


def test_an_edit_session_records_and_replays_to_the_same_saved_clip(tmp_path):
    """A drag on a keypoint's arrow and Ctrl+S, recorded; the replay repeats the edit bit for bit."""
    import os
    import subprocess
    import sys

    import numpy as np
    import pygame

    from authoring.edit_tool import reopen_edit
    from authoring.mocurves import save_session
    from authoring.session import Session
    from engine.runner import Runner, RunOptions
    from input.hub import InputHub
    from input.recording import read_recording
    from input.replay import ReplaySource

    out, rec = tmp_path / "walk_edited.ppclip", tmp_path / "edit.rec"
    act = build_edit("walk", (640, 360), out, record=rec)
    before = act.simulation.session.clip.rotations.copy()

    def send(kind, **fields):
        assert act.on_event(pygame.event.Event(kind, **fields), None)

    def steps(n=1):
        for _ in range(n):
            act.step()

    steps(3)
    send(pygame.KEYDOWN, key=pygame.K_2, mod=0)  # arrows mode: drag rotates the item around the view axis
    send(pygame.KEYDOWN, key=pygame.K_SPACE, mod=0)  # pause the loop so the keypoint stays put
    steps(2)
    edit = act.simulation.edit
    screen = edit.camera.project(edit.session.curves()[edit.item].positions, *edit.size)
    k = int(np.nanargmin(np.linalg.norm(screen - np.array([320.0, 180.0]), axis=1)))
    x, y = (int(round(v)) for v in screen[k])
    send(pygame.MOUSEBUTTONDOWN, button=1, pos=(x, y))
    steps()
    for dx in range(8, 48, 8):
        send(pygame.MOUSEMOTION, pos=(x + dx, y), rel=(8, 0), buttons=(1, 0, 0))
        steps()
    send(pygame.MOUSEBUTTONUP, button=1, pos=(x + 48, y))
    steps(2)
    send(pygame.KEYDOWN, key=pygame.K_s, mod=pygame.KMOD_CTRL)
    steps(3)
    act.recorder.close()
    assert out.exists() and not np.allclose(read_clip_rotations(out), before), "the drag edited nothing"

    env = {**os.environ, "SDL_VIDEODRIVER": "dummy"}
    done = subprocess.run(
        [sys.executable, "-m", "puppetphone", "replay", str(rec), "--verify", "--headless"],
        capture_output=True,
        text=True,
        env=env,
        cwd=tmp_path,
        timeout=300,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert f"replayed {act.frame} frames, all {act.frame} state hashes match" in done.stdout

    recording = read_recording(rec)
    replayed = Session(reopen_edit(recording.header.setup), InputHub(replay=ReplaySource(recording)))
    runner = Runner(RunOptions(headless=True))
    runner.run(replayed)
    again = tmp_path / "again.ppclip"
    save_session(replayed.simulation.session, again)
    assert again.read_bytes() == out.read_bytes()


def read_clip_rotations(path):
    from engine.clipfile import load_clip

    return load_clip(path).rotations


def test_a_take_opens_as_the_loop_of_the_part_picked(tmp_path, mocap_dir):
    from engine.clipfile import load_clip
    from engine.render import egl_available

    if (reason := egl_available()) is not None:
        pytest.skip(f"no headless GL: {reason}")
    out = tmp_path / "loop.ppclip"
    take = str(mocap_dir / "cmu_16_15_walk_daz.bvh")
    args = parse(
        take, "--start", "0.1", "--end", "390f", "--headless", "--frames", "2", "--size", "160x90", "--export", str(out)
    )
    assert run_edit(args) == 0
    clip = load_clip(out)
    assert clip.loop and clip.duration == pytest.approx(1.17, rel=0.04)
    assert run_edit(parse(take, "--start", "0", "--end", "0.5", "--headless", "--frames", "1")) == 2
    assert run_edit(parse("walk", "--start", "0", "--headless", "--frames", "1")) == 2


@pytest.mark.parametrize("blocker", ["folder", "full disk"])
def test_a_failed_ctrl_s_says_so_and_the_session_goes_on(tmp_path, capsys, blocker):
    """A folder in the way or a full disk: one line, the edit stays open, a later Ctrl+S elsewhere works."""
    from tests.faults import full_disk

    def ctrl_s(act):
        act.hub.tool("key", "s", True, False)
        act.step()

    if blocker == "folder":
        out = tmp_path / "walk_edited.ppclip"
        out.mkdir()
        act = build_edit("walk", (320, 180), out)
        ctrl_s(act)
    else:
        with full_disk(tmp_path / "disk") as disk:
            out = disk / "walk_edited.ppclip"
            act = build_edit("walk", (320, 180), out)
            ctrl_s(act)
            assert not out.exists()
    assert act.simulation.edit.message.startswith("NOT saved") and "cannot save" in act.simulation.edit.message
    err = capsys.readouterr().err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1
    act.step()
    act.simulation.output = tmp_path / "elsewhere.ppclip"
    ctrl_s(act)
    assert act.simulation.edit.message == f"saved {act.simulation.output}" and act.simulation.output.stat().st_size > 0
