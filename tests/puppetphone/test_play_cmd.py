"""``puppetphone play`` and ``replay`` as a user types them: recordings that replay anywhere.

Every command runs as a subprocess with the user's data folder pointed at a temporary
one, so nothing here reads or writes the real user's saves.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from engine.render.headless import egl_available
from games.tasbada.quest import Mark
from games.tasbada.save import Progress, save_progress
from input.recording import read_recording

needs_egl = pytest.mark.skipif(egl_available() is not None, reason=f"no EGL: {egl_available()}")


def puppetphone(*args: str, cwd: Path, data: Path) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "SDL_VIDEODRIVER": "dummy", "XDG_DATA_HOME": str(data)}
    for name in ("TASBADA_SAVE", "TASBADA_PHOTO", "TASBADA_SELFIE", "SNOWMAN_FIELD"):
        env.pop(name, None)
    return subprocess.run(
        [sys.executable, "-m", "puppetphone", *args], cwd=cwd, env=env, capture_output=True, text=True, timeout=600
    )


def test_a_tasbada_game_started_from_a_save_replays_from_its_file_alone(tmp_path: Path) -> None:
    save = tmp_path / "journey.json"
    marks = [Mark("box", np.array([[0.2, 0.3], [0.4, 0.6]]))]
    save_progress(save, Progress(["real", "props alive"], marks, 0.71, "props alive"))
    before = save.read_bytes()
    done = puppetphone(
        "play",
        "tasbada",
        "--headless",
        "--frames",
        "90",
        "--set",
        f"save={save}",
        "--set",
        "webcam=off",
        "--record",
        "from_save.rec",
        cwd=tmp_path,
        data=tmp_path / "data",
    )
    assert done.returncode == 0, done.stderr
    setup = read_recording(tmp_path / "from_save.rec").header.setup
    assert setup["reached"] == ["real", "props alive"] and setup["ground_v"] == pytest.approx(0.71)
    assert len(setup["marks"]) == 1
    save.unlink()  # the replay must need nothing but the recording
    done = puppetphone("replay", "from_save.rec", "--verify", "--headless", cwd=tmp_path, data=tmp_path / "other")
    assert done.returncode == 0, done.stdout + done.stderr
    assert "replayed 90 frames, all 90 state hashes match" in done.stdout
    assert not save.exists() and not (tmp_path / "other").exists()  # a replay writes nobody's files
    assert before  # the live game read the save it was given


def test_a_sandbox_scene_is_a_game_option_and_replays(tmp_path: Path) -> None:
    done = puppetphone(
        "play",
        "sandbox",
        "--headless",
        "--frames",
        "30",
        "--set",
        "scene=big_ball",
        "--record",
        "s.rec",
        cwd=tmp_path,
        data=tmp_path,
    )
    assert done.returncode == 0, done.stderr
    assert read_recording(tmp_path / "s.rec").header.setup == {"scene": "big_ball", "puppets": 1}
    assert puppetphone("replay", "s.rec", "--verify", "--headless", cwd=tmp_path, data=tmp_path).returncode == 0
    wrong = puppetphone("play", "sandbox", "--headless", "--set", "scene=moon", cwd=tmp_path, data=tmp_path)
    assert wrong.returncode == 2 and "scene 'moon' is not one of" in wrong.stderr
    wrong = puppetphone("play", "sandbox", "--headless", "--set", "gravity=0", cwd=tmp_path, data=tmp_path)
    assert wrong.returncode == 2 and "no option 'gravity'" in wrong.stderr


@needs_egl
def test_replay_screenshot_writes_the_final_frame_or_a_chosen_one(tmp_path: Path) -> None:
    rec = Path(__file__).resolve().parents[1] / "data" / "puppet_walk_run.rec"
    done = puppetphone(
        "replay",
        str(rec),
        "--verify",
        "--headless",
        "--size",
        "320x180",
        "--screenshot",
        "end.png",
        cwd=tmp_path,
        data=tmp_path,
    )
    assert done.returncode == 0, done.stderr
    assert "state hashes match" in done.stdout and "screenshot: end.png" in done.stdout
    done = puppetphone(
        "replay",
        str(rec),
        "--headless",
        "--size",
        "320x180",
        "--screenshot",
        "start.png",
        "--screenshot-at",
        "1",
        cwd=tmp_path,
        data=tmp_path,
    )
    assert done.returncode == 0, done.stderr
    end, start = (np.asarray(Image.open(tmp_path / n), dtype=float) for n in ("end.png", "start.png"))
    assert end.shape == (180, 320, 3) and end.std() > 0.05 * 255
    assert np.abs(end - start).mean() > 1.0  # the puppet walked away: the final frame is not the first
    assert oct((tmp_path / "end.png").stat().st_mode & 0o777) == oct(0o666 & ~_umask())


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


@pytest.mark.parametrize(
    "args, says",
    [
        (["play", "snowman", "--headless", "--frames", "-5"], "-5 is out of range"),
        (["play", "snowman", "--headless", "--size", "0x0"], "out of range"),
        (["play", "snowman", "--headless", "--screenshot", "x.bmp"], "use .png or .jpg"),
        (["replay", "x.rec", "--headless", "--quality", "ultra"], "quality must be one of low, medium, high, auto"),
        (["author", "edit", "walk", "--headless", "--bogus"], "usage: puppetphone author edit"),
        (["play", "snowman", "--bogus"], "usage: puppetphone play"),
        (
            ["author", "edit", "walk", "--headless", "--export", "x.fbx"],
            "cannot export x.fbx: use one of .bvh, .glb, .gltf, .ppclip",
        ),
        (
            ["author", "edit", str(Path(__file__).resolve().parents[2] / "README.md"), "--headless"],
            "is not a clip file",
        ),
        (["cycle", "in.bvh", "-o", "out.ppclip", "--plot", "x.gif"], "use .png or .jpg"),
    ],
)
def test_bad_command_lines_say_what_is_wrong_with_the_subcommand_usage(
    tmp_path: Path, args: list[str], says: str
) -> None:
    done = puppetphone(*args, cwd=tmp_path, data=tmp_path)
    assert done.returncode == 2 and says in done.stderr and "Traceback" not in done.stderr


def test_version(tmp_path: Path) -> None:
    done = puppetphone("--version", cwd=tmp_path, data=tmp_path)
    assert done.returncode == 0 and done.stdout.startswith("puppetphone ")
    assert len(done.stdout.splitlines()) == 1


@needs_egl
def test_the_start_screen_leaves_the_puppet_in_sight_at_any_window_size_and_shows_a_real_fps(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import re

    monkeypatch.setenv("PUPPETPHONE_HUD_DUMP", str(tmp_path / "hud.txt"))
    for size in ("1280x720", "640x360"):
        done = puppetphone(
            "play",
            "snowman",
            "--headless",
            "--frames",
            "90",
            "--size",
            size,
            "--screenshot",
            f"{size}.png",
            cwd=tmp_path,
            data=tmp_path / "data",
        )
        assert done.returncode == 0, done.stderr
        # The mouse is a person's hand: a headless run with it is paced to real time, and the HUD says how fast
        # it went (flat out it would be hundreds of steps a second; it said 0.0 before).
        fps = float(re.search(r"([0-9.]+) fps", (tmp_path / "hud.txt").read_text(encoding="utf-8")).group(1))
        assert 20.0 < fps < 75.0, f"the HUD says {fps} fps for a run paced at 60 steps a second"
        shot = np.asarray(Image.open(tmp_path / f"{size}.png").convert("RGB"), dtype=np.float64) / 255.0
        r, g, b = shot[..., 0], shot[..., 1], shot[..., 2]
        h, w = r.shape
        puppet = (r > g + 0.25) & (r > b + 0.25)
        assert puppet[h // 4 : 3 * h // 4, w // 3 : 2 * w // 3].sum() > 0.0004 * h * w, f"{size}: the puppet is hidden"
        panels = (np.ptp(shot, axis=2) < 0.03) & (shot.mean(axis=2) < 0.35)  # the text's dark panels
        assert panels.mean() < 0.2, f"{size}: the overlay covers {panels.mean():.0%} of the window"
