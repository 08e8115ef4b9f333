"""Tasbada's new options as a user types them: a bad ``light`` or ``pose`` is one clear line and a failure."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest


def _play(*sets: str, tmp: Path) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "SDL_VIDEODRIVER": "dummy", "SDL_AUDIODRIVER": "dummy", "XDG_DATA_HOME": str(tmp)}
    for name in ("TASBADA_SAVE", "TASBADA_PHOTO", "TASBADA_SELFIE"):
        env.pop(name, None)
    args = [a for s in sets for a in ("--set", s)]
    return subprocess.run(
        [
            sys.executable,
            "-m",
            "puppetphone",
            "play",
            "tasbada",
            "--headless",
            "--frames",
            "5",
            "--set",
            "webcam=off",
            *args,
        ],
        cwd=tmp,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )


@pytest.mark.parametrize(
    ("option", "says"),
    [
        ("light=north", "tasbada light must be a number of degrees, not 'north'"),
        ("light=nan", "tasbada light must be a finite number"),
        ("pose=maybe", "tasbada pose must be auto or off, not 'maybe'"),
    ],
)
def test_a_bad_option_is_one_clear_line(option: str, says: str, tmp_path: Path) -> None:
    done = _play(option, tmp=tmp_path)
    assert done.returncode != 0
    errors = [ln for ln in done.stderr.splitlines() if ln.startswith("error:")]
    assert len(errors) == 1 and says in errors[0]
    assert "Traceback" not in done.stderr


def test_pose_off_and_a_light_angle_start_the_game(tmp_path: Path) -> None:
    done = _play("pose=off", "light=30", tmp=tmp_path)
    assert done.returncode == 0, done.stderr
    assert "Traceback" not in done.stderr and "pose:" not in done.stderr  # no estimator ran
    assert "stage: real" in done.stdout
