"""The command line as a newcomer meets it: help that says what each scene is, one clear line when
something optional is missing, and a replay that needs a display only for its window."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]


def run(args: list[str], cwd: Path, env: dict[str, str] | None = None, code: str | None = None):  # type: ignore[no-untyped-def]
    command = [sys.executable, "-c", code, *args] if code else [sys.executable, "-m", "puppetphone", *args]
    return subprocess.run(
        command,
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=300,
        env=env or {**os.environ, "SDL_VIDEODRIVER": "dummy"},
    )


def test_authoring_scenes_have_descriptions(tmp_path: Path) -> None:
    for scene, words in (("record", "act a cycle out"), ("edit", "refine a cycle with MoCurves")):
        done = run(["author", scene, "--help"], tmp_path)
        assert done.returncode == 0 and words in done.stdout.split("options:")[0]


def test_cycle_plot_without_matplotlib_says_so_in_one_line(tmp_path: Path) -> None:
    no_matplotlib = (
        "import sys; sys.modules['matplotlib'] = None; from puppetphone.cli import main; "
        "sys.argv[0] = 'puppetphone'; raise SystemExit(main(sys.argv[1:]))"
    )
    bvh = REPO / "tests" / "data" / "puppet_walk_run.rec"
    done = run(["cycle", str(bvh), "-o", "loop.ppclip", "--plot", "loop.png"], tmp_path, code=no_matplotlib)
    assert done.returncode == 2
    assert done.stderr.strip() == "cycle: --plot needs matplotlib: pip install 'puppetphone[plot]'"


def test_replay_without_headless_needs_a_display_and_says_how_to_do_without(tmp_path: Path) -> None:
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY", "SDL_VIDEODRIVER")}
    done = run(["replay", str(REPO / "tests" / "data" / "puppet_jump_stop.rec")], tmp_path, env=env)
    assert done.returncode == 2 and "no display" in done.stderr and "--headless" in done.stderr
    done = run(["replay", str(REPO / "tests" / "data" / "puppet_jump_stop.rec"), "--headless"], tmp_path)
    assert done.returncode == 0 and "replayed 100 frames" in done.stdout


def test_top_level_help_names_every_game(tmp_path: Path) -> None:
    from puppetphone.games import GAMES

    done = run(["--help"], tmp_path)
    play_line = next(line for line in done.stdout.splitlines() if line.strip().startswith("play"))
    assert all(name in play_line for name in GAMES), play_line


def test_set_help_lists_every_games_options_with_types_ranges_and_defaults(tmp_path: Path) -> None:
    from puppetphone.games import GAMES, load_game

    done = run(["play", "snowman", "--set", "help"], tmp_path)
    assert done.returncode == 0, done.stderr
    for name in GAMES:
        assert f"\n{name}:\n" in done.stdout
        for key in load_game(name).options:
            line = next(li for li in done.stdout.splitlines() if li.strip().startswith(key + " "))
            assert len(line.split()) > 3, line  # a type or range and what it does, not the bare name
    assert "empty|small_ball|big_ball" in done.stdout and "1–1000" in done.stdout and "default auto" in done.stdout
