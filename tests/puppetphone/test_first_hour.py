"""A newcomer's first hour, scripted: real windows under Xvfb driven by xdotool, as a person would drive them.

One test, three programs, in the order the README leads a newcomer through them:

1. ``play snowman``: the field shows the puppet on snow; H hides and brings back the help; V with the
   mouse says why nothing happens; grab the puppet and walk it; crouch (wheel down) and roll a
   snowball; F9 brings back a saved field (two snowballs beside the puppet); a flick makes the
   puppet jump; lifting the small ball onto the big one brings a snowman to life; F5 saves the
   field; Esc quits with exit code 0.
2. ``author record``: the first take — the screen says to hold the left button; a click on the figure
   picks the joint; R, the count-down, a few circles with the button held, a loop is found; Enter
   accepts and saves.
3. ``play tasbada`` from a journey saved at the mixed stage: the menu's Continue, then the avatar is
   walked to the first cage and frees its creature.

What the person sees is checked from the X server's screen (pixel statistics) and from the HUD's
text, which the runner writes to ``$PUPPETPHONE_HUD_DUMP`` (the game's own state dump); where to
click is found with the game's own camera, as the person finds it with their eyes.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from tests.puppetphone.xvfb import needs_x

SIZE = (640, 360)
pytestmark = [needs_x, pytest.mark.skipif(shutil.which("xdotool") is None, reason="needs xdotool (Debian xdotool)")]


class Window:
    """One ``puppetphone`` command in a real window, driven with xdotool; its HUD read from the dump file."""

    def __init__(self, display: str, tmp: Path, args: list[str]) -> None:
        self.display, self.tmp = display, tmp
        self.hud_file = tmp / f"hud_{args[1]}.txt"
        self.env = {
            **os.environ,
            "DISPLAY": display,
            "SDL_VIDEODRIVER": "x11",
            "XDG_DATA_HOME": str(tmp / "data"),
            "PUPPETPHONE_HUD_DUMP": str(self.hud_file),
            "SDL_VIDEO_X11_WMCLASS": "puppetphone",
        }
        for name in ("TASBADA_SAVE", "TASBADA_PHOTO", "TASBADA_SELFIE", "SNOWMAN_FIELD"):
            self.env.pop(name, None)
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "puppetphone", *args, "--size", f"{SIZE[0]}x{SIZE[1]}"],
            env=self.env,
            cwd=tmp,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        self.id = ""
        self.wait(lambda: self._find_window() and self.hud_file.exists(), 60, "the window to open and draw")
        self.xdo("windowfocus", "--sync", self.id)

    def _find_window(self) -> bool:
        found = subprocess.run(
            ["xdotool", "search", "--classname", "puppetphone"], env=self.env, capture_output=True, text=True
        )
        self.id = found.stdout.split()[0] if found.stdout.split() else ""
        return bool(self.id)

    def xdo(self, *args: object) -> None:
        subprocess.run(["xdotool", *map(str, args)], env=self.env, check=True, timeout=20, capture_output=True)

    def hud(self) -> str:
        try:
            return self.hud_file.read_text(encoding="utf-8")
        except FileNotFoundError:
            return ""

    def wait(self, ok: Callable[[], object], seconds: float, what: str) -> None:
        deadline = time.monotonic() + seconds
        while not ok():
            if self.proc.poll() is not None:
                out, err = self.proc.communicate()
                pytest.fail(f"the program ended while waiting for {what}:\n{out}\n{err}")
            assert time.monotonic() < deadline, f"waited {seconds} s for {what}; the HUD says:\n{self.hud()}"
            time.sleep(0.1)

    def sees(self, text: str, seconds: float = 10.0) -> None:
        self.wait(lambda: text in self.hud(), seconds, repr(text))

    def screen(self) -> np.ndarray:
        """The window as the X server shows it, RGB in [0, 1]."""
        path = self.tmp / "window.png"
        subprocess.run(
            ["import", "-display", self.display, "-window", self.id, str(path)],
            check=True,
            timeout=30,
            capture_output=True,
        )
        return np.asarray(Image.open(path).convert("RGB"), dtype=np.float64) / 255.0

    def move(self, px: tuple[float, float]) -> None:
        self.xdo("mousemove", "--window", self.id, int(round(px[0])), int(round(px[1])))

    def drag(self, pixels: list[tuple[float, float]], pause: float = 0.08) -> None:
        for px in pixels:
            self.move(px)
            time.sleep(pause)

    def flick(self, pixels: list[tuple[float, float]]) -> None:
        """Moves as fast as a hand flicks: one xdotool run, not one process per move (on a loaded
        machine a process each spread the moves over more than the flick's 0.15 s)."""
        moves: list[object] = []
        for px in pixels:
            moves += ["mousemove", "--window", self.id, int(round(px[0])), int(round(px[1])), "sleep", "0.01"]
        self.xdo(*moves)

    def key(self, name: str) -> None:
        self.xdo("key", name)

    def quit(self) -> subprocess.CompletedProcess[str]:
        self.key("Escape")
        try:
            out, err = self.proc.communicate(timeout=30)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            out, err = self.proc.communicate()
            pytest.fail(f"Esc did not quit:\n{out}\n{err}")
        return subprocess.CompletedProcess(self.proc.args, self.proc.returncode, out, err)

    def close(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.communicate()


def _red(screen: np.ndarray) -> np.ndarray:
    r, g, b = screen[..., 0], screen[..., 1], screen[..., 2]
    return (r > g + 0.25) & (r > b + 0.25)


def _centroid(mask: np.ndarray) -> np.ndarray:
    ys, xs = np.nonzero(mask)
    assert len(xs) > 20, "nothing of that colour on the screen"
    return np.array([xs.mean(), ys.mean()])


def _path(camera, a: np.ndarray, b: np.ndarray, n: int) -> list[tuple[float, float]]:  # type: ignore[no-untyped-def]
    points = [a + (b - a) * k / n for k in range(1, n + 1)]
    return [tuple(camera.project(p[None], *SIZE)[0]) for p in points]


def _snowman_field(path: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A saved field (the game's own format): the puppet at the origin, a big and a small snowball beside it."""
    from games.snowman.field_save import snapshot
    from games.snowman.rules import spawn_ball
    from input.hub import InputHub
    from puppetphone.games import make_app

    app = make_app("snowman", 0, InputHub())
    big, small = np.array([1.4, 0.45, 0.9]), np.array([-1.3, 0.22, 1.3])
    spawn_ball(app.world, big, 0.45)
    spawn_ball(app.world, small, 0.22)
    path.write_text(json.dumps(snapshot(app.world)), encoding="utf-8")
    return np.zeros(3), big, small


def _play_snowman(display: str, tmp: Path) -> None:
    from games.snowman.game import camera

    cam = camera()
    field = tmp / "field.json"
    _, big, small = _snowman_field(field)
    w = Window(display, tmp, ["play", "snowman", "--set", f"field={field}"])
    try:
        # Start: the puppet stands on snow in the middle, the help is up but leaves it in sight.
        w.sees("puppet: standing")
        screen = w.screen()
        snow = (screen.min(axis=2) > 0.75).mean()
        assert snow > 0.4, f"only {snow:.0%} of the window is snow"
        hips = cam.project(np.array([[0.0, 0.95, 0.0]]), *SIZE)[0]
        assert np.linalg.norm(_centroid(_red(screen)) - hips) < 40, "the red puppet is not where it stands"
        assert "mouse: press on the puppet" in w.hud() and "web:" not in w.hud()

        # Help: H hides it (the hint to bring it back stays), F1 shows it again.
        w.key("h")
        w.wait(
            lambda: "mouse: press on the puppet" not in w.hud() and "H / F1: help" in w.hud(), 10, "the help to hide"
        )
        w.key("F1")
        w.sees("mouse: press on the puppet")

        # V with the mouse: nothing to see from, and the screen says so.
        w.key("v")
        w.sees("no held controller to see from")

        # Grab the puppet by its hips and walk it to the right.
        w.move(hips)
        time.sleep(0.3)
        w.xdo("mousedown", "1")
        w.drag(_path(cam, np.array([0.0, 0.95, 0.0]), np.array([1.2, 0.95, -0.3]), 12))
        w.sees("puppet: walking")
        w.wait(lambda: "puppet: standing" in w.hud(), 10, "the puppet to stop where it was led")
        moved = _centroid(_red(w.screen()))
        assert moved[0] > hips[0] + 25, f"the puppet did not walk right: {hips} -> {moved}"

        # Crouch (wheel down) and crouch-walk back over fresh snow: a snowball is started and rolled.
        for _ in range(4):
            w.xdo("click", "5")
            time.sleep(0.1)
        w.sees("puppet: crouch")
        w.drag(_path(cam, np.array([1.2, 0.55, -0.3]), np.array([0.2, 0.55, -0.9]), 14), pause=0.12)
        w.sees("rolling a snowball")
        w.sees("snowballs started: 1")
        for _ in range(4):
            w.xdo("click", "4")
            time.sleep(0.1)
        w.xdo("mouseup", "1")

        # F9: the saved field comes back (the notice says so), the puppet at the origin between two balls.
        w.key("F9")
        w.sees("field restored")
        w.sees("snowballs started: 0")

        # Jump: grab the puppet again and flick the mouse up.
        w.move(hips)
        time.sleep(0.3)
        w.xdo("mousedown", "1")
        time.sleep(0.6)
        x, y = hips
        w.flick([(x, y - 30), (x, y - 60), (x, y - 90), (x, y - 110)])
        w.wait(lambda: any(word in w.hud() for word in ("ready to jump", "in the air", "landing")), 10, "a jump")
        w.drag([(x, y)], pause=0.3)
        w.xdo("mouseup", "1")
        w.wait(lambda: "puppet: standing" in w.hud(), 15, "the puppet to land and stand")

        # Stack: grab the small ball, lift it (wheel up, the cursor kept over it), carry it over the big one.
        w.move(cam.project(small[None], *SIZE)[0])
        time.sleep(0.3)
        w.xdo("mousedown", "1")
        time.sleep(0.3)
        lifted = small.copy()
        for _ in range(10):
            lifted[1] += 0.1
            w.move(cam.project(lifted[None], *SIZE)[0])
            w.xdo("click", "4")
            time.sleep(0.08)
        above = np.array([big[0], lifted[1], big[2]])
        w.drag(_path(cam, lifted, above, 14), pause=0.12)
        time.sleep(1.0)
        w.xdo("mouseup", "1")
        w.sees("snowmen built: 1", 20)

        # F5 saves the field with its snowman; Esc quits cleanly.
        w.key("F5")
        w.sees("field saved")
        w.wait(lambda: len(json.loads(field.read_text(encoding="utf-8"))["snowmen"]) == 1, 10, "the saved snowman")
        done = w.quit()
        assert done.returncode == 0 and "ran " in done.stdout, done.stderr
    finally:
        w.close()


def _first_take(display: str, tmp: Path) -> None:
    from authoring.record_scene import RecordScene
    from engine.fk import forward_kinematics
    from engine.humanoid import humanoid_skeleton

    sk = humanoid_skeleton()
    scene = RecordScene(sk, "r_upper_arm")
    wpos, _ = forward_kinematics(sk, *scene._pose(0.0, None))
    forearm = scene.camera.project(((wpos[sk.index("l_lower_arm")] + wpos[sk.index("l_hand")]) / 2)[None], *SIZE)[0]
    out = tmp / "arm.ppclip"
    w = Window(display, tmp, ["author", "record", "--countdown", "1", "--seconds", "5", "-o", str(out)])
    try:
        w.sees("hold the left button")
        w.move(forearm)
        w.xdo("click", "1")
        w.sees("driving l_lower_arm")
        w.key("r")
        w.sees("recording", 10)
        centre = np.array([SIZE[0] * 0.5, SIZE[1] * 0.5])
        w.move(centre + [60, 0])
        w.xdo("mousedown", "1")
        start = time.monotonic()
        while "preview" not in w.hud() and time.monotonic() - start < 20:  # circles of about a second
            t = time.monotonic() - start
            w.move(centre + 60 * np.array([np.cos(2 * np.pi * t), np.sin(2 * np.pi * t)]))
            time.sleep(0.03)
        w.xdo("mouseup", "1")
        w.sees("loop of")
        w.key("Return")
        w.sees("layer accepted and saved")
        assert w.quit().returncode == 0 and out.is_file()
    finally:
        w.close()


def _tasbada_to_the_cages(display: str, tmp: Path) -> None:
    from engine.components import Transform
    from engine.statemachine.puppet.body import PuppetBody
    from games.tasbada.flow import restart_from
    from games.tasbada.game import GAME
    from games.tasbada.marking import menu_buttons
    from games.tasbada.objects import Creature
    from games.tasbada.quest import MIXED, PROPS_ALIVE, REAL, Mark, Quest
    from games.tasbada.save import Progress, save_progress
    from games.tasbada.view import game_camera
    from input.hub import InputHub
    from puppetphone.games import make_app

    save = tmp / "journey.json"
    pot = Mark("box", np.array([[0.49, 0.52], [0.675, 0.845]]))
    save_progress(save, Progress([REAL, PROPS_ALIVE, MIXED], [pot], 0.71, MIXED))
    # Where the avatar and the cages stand once the journey continues (the same world, built here from the save).
    options = {**GAME.options, "save": str(save), "webcam": "off", "pose": "off"}
    app = make_app("tasbada", 0, InputHub(), GAME.prepare(options))
    app.step()
    q = app.world.resource(Quest)
    restart_from(app.world, q, MIXED)
    app.step()
    ((_, _, tr),) = app.world.query(PuppetBody, Transform)
    avatar = tr.position + np.array([0.0, 0.95, 0.0])
    home = min((c.home for _, c in app.world.query(Creature)), key=lambda h: np.linalg.norm(h - tr.position))
    cam = game_camera()
    cont = menu_buttons([REAL, PROPS_ALIVE, MIXED], True)[-1].rect
    sets = [a for k in ("save", "webcam", "pose") for a in ("--set", f"{k}={options[k]}")]
    w = Window(display, tmp, ["play", "tasbada", *sets])
    try:
        w.sees("stage 0/4: menu")
        w.move(((cont[0] + cont[2]) / 2 * SIZE[0], (cont[1] + cont[3]) / 2 * SIZE[1]))
        time.sleep(0.3)
        w.xdo("click", "1")
        w.sees("creatures freed 0/3")
        w.move(cam.project(avatar[None], *SIZE)[0])
        time.sleep(0.3)
        w.xdo("mousedown", "1")
        w.drag(_path(cam, avatar, np.array([home[0], avatar[1], home[2]]), 20), pause=0.12)
        w.sees("creatures freed 1/3", 20)
        w.xdo("mouseup", "1")
        assert w.quit().returncode == 0
    finally:
        w.close()


def test_the_first_hour_in_real_windows(display: str, tmp_path: Path) -> None:
    _play_snowman(display, tmp_path)
    _first_take(display, tmp_path)
    _tasbada_to_the_cages(display, tmp_path)
