"""Mocap to a walking puppet, as a user types it: ``cycle --retarget puppet`` -> ``clips add`` -> ``play --clips``.

The CMU walk (shared/data/mocap) is cut to a loop on the puppet, added as the walk, and
the sandbox puppet is walked by a scripted phone (a recorded stick, replayed through
``play --source replay:…``) with the authored clips and with the built-in ones. The
puppet must keep to the stick's speed (within the blend's 5 % bar) and its planted feet
must not slide (under 2 cm/s), with either clip set walked at both walks' speeds (see
:mod:`puppetphone.clip_walk` for the figures).
The recording made with the library replays bit for bit after the library is gone, and
a user's default library changes no replay of a recording made without it.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from engine.clips import default_clips
from puppetphone.clip_walk import record_stick_walk, walk_figures

BLEND_BAR_PCT = 5.0
SLIDE_BAR = 0.02  # m/s: planted feet in play (issue 28's bar), for mocap and built-in clips alike


def _run(*args: str, env: dict[str, str], cwd: Path) -> subprocess.CompletedProcess[str]:
    out = subprocess.run(
        [sys.executable, "-m", "puppetphone", *args], capture_output=True, text=True, env=env, cwd=cwd, timeout=300
    )
    assert out.returncode == 0, f"puppetphone {' '.join(args)}: {out.stderr}"
    return out


@pytest.fixture
def env(tmp_path: Path) -> dict[str, str]:
    """A user whose data and cache folders are in the test's folder."""
    return dict(
        os.environ,
        SDL_VIDEODRIVER="dummy",
        SDL_AUDIODRIVER="dummy",
        XDG_DATA_HOME=str(tmp_path / "data"),
        XDG_CACHE_HOME=str(tmp_path / "cache"),
    )


def test_cmu_walk_reaches_the_game(mocap_dir: Path, tmp_path: Path, env: dict[str, str]) -> None:
    _run(
        "cycle",
        str(mocap_dir / "cmu_16_15_walk_daz.bvh"),
        "--retarget",
        "puppet",
        "-o",
        "walk.ppclip",
        env=env,
        cwd=tmp_path,
    )
    added = _run("clips", "add", "walk.ppclip", "--role", "walk", "--clips", "lib", env=env, cwd=tmp_path)
    assert "added walk.ppclip as the walk" in added.stdout
    listed = _run("clips", "list", "--clips", "lib", env=env, cwd=tmp_path).stdout
    assert "walk" in listed and "loop" in listed

    from engine.cliplib.library import ClipLibrary

    own_speed = ClipLibrary(tmp_path / "lib").load()["walk"].average_speed()
    builtin_speed = default_clips()["walk"].average_speed()
    # Both clip sets walked at both walks' speeds: a set is never judged at an easier speed.
    figures = {}
    for name, speed in (("own", own_speed), ("builtin", builtin_speed)):
        record_stick_walk(tmp_path / f"stick_{name}.rec", speed=speed)
        for clips, extra in (("authored", ["--clips", "lib"]), ("builtin", [])):
            out = f"{clips}_at_{name}.rec"
            _run(
                "play",
                "sandbox",
                "--headless",
                *extra,
                "--source",
                f"replay:stick_{name}.rec",
                "--record",
                out,
                env=env,
                cwd=tmp_path,
            )
            figures[clips, name] = walk_figures(tmp_path / out)
    for (clips, name), fig in sorted(figures.items()):
        print(f"{clips} clips at the {name} walk's speed: {fig}")
        assert fig.requested == pytest.approx(own_speed if name == "own" else builtin_speed, rel=0.02)
        assert fig.speed_error_pct < BLEND_BAR_PCT
        assert fig.foot_slide <= SLIDE_BAR, (clips, name, fig)

    # A second start with the same clips reads the measured table from the cache: one table for
    # the authored library and one for the built-in set, however many sessions started.
    cached = list((tmp_path / "cache" / "puppetphone" / "lookup").glob("*.npz"))
    assert len(cached) == 2

    # The recording carries its clips: it replays with them after the library is gone.
    shutil.rmtree(tmp_path / "lib")
    verified = _run("replay", "authored_at_own.rec", "--verify", "--headless", env=env, cwd=tmp_path)
    assert "state hashes match" in verified.stdout


def test_a_default_library_changes_no_replay(tmp_path: Path, env: dict[str, str]) -> None:
    """The user's library (XDG_DATA_HOME) plays live, never in a replay of a session recorded without it."""
    from engine.cliplib.library import ClipLibrary, default_library_dir
    from engine.cliplib.roles import conform
    from engine.humanoid import humanoid_skeleton

    lib = Path(env["XDG_DATA_HOME"]) / "puppetphone" / "clips"
    brisk = default_clips()["walk"].resampled(50.0)
    ClipLibrary(lib).add(conform(brisk, "walk"), "walk", humanoid_skeleton(), default_clips())
    assert lib.parent.parent == Path(env["XDG_DATA_HOME"]) and default_library_dir() != lib
    shipped = Path(__file__).resolve().parents[1] / "data" / "puppet_walk_run.rec"
    out = _run("replay", str(shipped), "--verify", "--headless", env=env, cwd=tmp_path)
    assert "state hashes match" in out.stdout
    # play from that recording without --clips: the recorded (built-in) clips, same hashes.
    _run(
        "play", "sandbox", "--headless", "--source", f"replay:{shipped}", "--record", "again.rec", env=env, cwd=tmp_path
    )
    from input.recording import read_recording

    assert read_recording(tmp_path / "again.rec").hashes == read_recording(shipped).hashes
    # A live session (a phone over OSC, nobody sending) does play the default library, and its recording says so.
    import socket

    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    _run(
        "play",
        "sandbox",
        "--headless",
        "--source",
        "osc",
        "--osc-port",
        str(port),
        "--frames",
        "20",
        "--record",
        "live.rec",
        env=env,
        cwd=tmp_path,
    )
    from engine.cliplib.embed import decode

    setup = read_recording(tmp_path / "live.rec").header.setup
    assert list(decode(setup["clips"], humanoid_skeleton())) == ["walk"]
    verified = _run("replay", "live.rec", "--verify", "--headless", env=env, cwd=tmp_path)
    assert "state hashes match" in verified.stdout
