"""A save that its file refuses, as a person meets it: the session runs on and the work is in the recovery folder.

Each command runs as a user types it, against a real fault (a full tmpfs, a read-only mount):
F5 in a snowman window and Ctrl+S in an ``author edit`` window are real key presses sent to
an X server (Xvfb, ``xdotool``; the ``display`` fixture of tests/puppetphone/xvfb.py, which picks a
free number itself and does not reset between clients); the tasbada progress and a growing
``--record`` run headless.
Each test then opens the recovered file the way the line says to.

Broken on purpose to see these fail: :class:`engine.recovery.Rescue` writing nothing after the
target refused (every test: no recovered file, the "NOT saved" line alone), and the recorder's
move removed (the recording stopped at frame ~50 of 150).
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

from tests.faults import full_disk, read_only_folder

needs_x = pytest.mark.skipif(
    not (shutil.which("Xvfb") and shutil.which("xdotool")),
    reason="needs Xvfb and xdotool (Debian xvfb xdotool) to press keys in a real window",
)


def _env(data: Path, **extra: str) -> dict[str, str]:
    env = {**os.environ, "SDL_VIDEODRIVER": "dummy", "XDG_DATA_HOME": str(data), **extra}
    for name in ("TASBADA_SAVE", "TASBADA_PHOTO", "TASBADA_SELFIE", "SNOWMAN_FIELD"):
        env.pop(name, None)
    return env


def _puppetphone(*args: str, data: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "puppetphone", *args],
        env=_env(data),
        capture_output=True,
        text=True,
        check=False,
        timeout=300,
    )


def _in_window(display: str, args: list[str], data: Path, keys: list[str], said: str) -> tuple[int, str, str]:
    """Run ``puppetphone ARGS`` in a window, press ``keys`` once it shows, wait for ``said`` on the
    terminal, press Escape; the exit code and both outputs."""
    env = _env(data, DISPLAY=display, SDL_VIDEODRIVER="x11")
    log_out, log_err = data.parent / "out.txt", data.parent / "err.txt"
    with open(log_out, "w") as out, open(log_err, "w") as err:
        proc = subprocess.Popen([sys.executable, "-m", "puppetphone", *args], env=env, stdout=out, stderr=err)
    try:
        deadline = time.monotonic() + 120  # a deadline for the test, not a measured time
        window = ""
        while not window:
            assert proc.poll() is None and time.monotonic() < deadline, log_err.read_text()
            found = subprocess.run(
                ["xdotool", "search", "--onlyvisible", "--name", ""],
                env=env,
                capture_output=True,
                text=True,
                check=False,
            )
            window = found.stdout.split()[-1] if found.stdout.split() else ""  # the only client of this X server
            time.sleep(0.2)
        subprocess.run(["xdotool", "windowfocus", "--sync", window], env=env, check=True, timeout=30)
        time.sleep(1.0)  # the window's first frames: SDL takes keys once its event loop runs
        while said not in log_out.read_text() + log_err.read_text():
            assert proc.poll() is None and time.monotonic() < deadline, log_err.read_text()
            subprocess.run(["xdotool", "key", *keys], env=env, check=True, timeout=30)
            time.sleep(1.0)
        subprocess.run(["xdotool", "key", "Escape"], env=env, check=True, timeout=30)
        code = proc.wait(60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait(10)
    return code, log_out.read_text(), log_err.read_text()


@needs_x
def test_f5_on_a_full_disk_keeps_playing_and_the_field_is_in_the_recovery_folder(tmp_path: Path, display: str) -> None:
    from games.snowman.field_save import load_field

    data = tmp_path / "data"
    with full_disk(tmp_path / "disk", free=2048) as disk:
        code, out, err = _in_window(
            display,
            ["play", "snowman", "--set", f"field={disk / 'field.json'}", "--size", "480x270"],
            data,
            ["F5"],
            "field NOT saved",
        )
        assert not (disk / "field.json").exists()
    recovered = data / "puppetphone" / "recovered" / "field.json"
    line = next(x for x in out.splitlines() if "NOT saved" in x)
    assert code == 0 and "Traceback" not in err, err
    assert "No space left" in line and f"--set field={recovered}" in line
    assert load_field(recovered) is not None
    again = _puppetphone("play", "snowman", "--headless", "--frames", "1", "--set", f"field={recovered}", data=data)
    assert again.returncode == 0 and "set aside" not in again.stderr, again.stderr


@needs_x
def test_ctrl_s_into_a_read_only_folder_keeps_the_edit_open_and_the_clip_reopens(tmp_path: Path, display: str) -> None:
    from engine.clipfile import load_clip

    data = tmp_path / "data"
    with read_only_folder(tmp_path / "ro") as ro:
        code, _, err = _in_window(
            display,
            ["author", "edit", "walk", "-o", str(ro / "walk_edited.ppclip"), "--size", "480x270"],
            data,
            ["ctrl+s"],
            "saved instead to",
        )
        assert not (ro / "walk_edited.ppclip").exists()
    recovered = data / "puppetphone" / "recovered" / "walk_edited.ppclip"
    assert code == 0 and "Traceback" not in err, err
    assert f"NOT saved to {ro / 'walk_edited.ppclip'}" in err and str(recovered) in err
    assert len(load_clip(recovered).rotations) > 1
    again = _puppetphone("author", "edit", str(recovered), "--headless", "--frames", "1", data=data)
    assert again.returncode == 0, again.stderr


def test_tasbada_progress_on_a_full_disk_is_kept_in_the_recovery_folder(tmp_path: Path) -> None:
    from games.tasbada.save import load_progress

    data = tmp_path / "data"
    with full_disk(tmp_path / "disk", free=512) as disk:
        done = _puppetphone(
            "play",
            "tasbada",
            "--headless",
            "--frames",
            "30",
            "--set",
            f"save={disk / 'journey.json'}",
            "--set",
            "webcam=off",
            data=data,
        )
    recovered = data / "puppetphone" / "recovered" / "journey.json"
    lines = [x for x in done.stderr.splitlines() if "NOT saved" in x]
    assert done.returncode == 0 and "Traceback" not in done.stderr and "ran 30 steps" in done.stdout + done.stderr, (
        done.stderr
    )
    assert len(lines) == 1 and f"--set save={recovered}" in lines[0]
    assert load_progress(recovered).stage == "real"


def test_a_recording_that_fills_the_disk_goes_on_in_the_recovery_folder_and_verifies(tmp_path: Path) -> None:
    data = tmp_path / "data"
    with full_disk(tmp_path / "disk", free=4096) as disk:
        done = _puppetphone(
            "play", "sandbox", "--headless", "--frames", "150", "--record", str(disk / "s.rec"), data=data
        )
    recovered = data / "puppetphone" / "recovered" / "s.rec"
    assert done.returncode == 0 and "Traceback" not in done.stderr, done.stderr
    assert f"it goes on in {recovered}" in done.stderr and f"recorded 150 frames to {recovered}" in done.stderr
    check = _puppetphone("replay", str(recovered), "--verify", "--headless", data=data)
    assert check.returncode == 0 and "all 150 state hashes match" in check.stdout + check.stderr, check.stderr
