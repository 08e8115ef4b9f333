"""Rebuild ``games/tasbada/demo.rec``: the whole journey, played through the real input path.

Run ``python -m tools.regen demos`` (or ``python -m tools.tasbada_demo [--screenshots DIR]``). Mouse events are
synthesised as pygame would deliver them for a 1280x720 window, handed to
:class:`input.mouse.MouseSource` with the game's camera, and each step is recorded by
:class:`input.recording.Recorder` — exactly what ``puppetphone play tasbada --record``
does with a real mouse. The script waits on the quest's state (a milestone reached,
the avatar arrived), so it always plays to the end; the events it sends depend only on
the simulation, so running it again writes the same recording.

The journey: mark the clay pot (a box), the plant (a lasso) and the lamp (a box),
nudge the floor line, press Done; click through the narrator's story; after the
selfie count-down grab the avatar and walk it to the three cages, over the five
crystals and through the gate; then wander in Tasbada.
"""

from __future__ import annotations

import argparse
from collections.abc import Iterator
from pathlib import Path
from types import SimpleNamespace

import numpy as np

import games.tasbada

__all__ = ["DEMO", "SIZE", "make_demo"]

DEMO = Path(games.tasbada.__file__).with_name("demo.rec")
SIZE = (1280, 720)
MOTION, DOWN, UP = 1024, 1025, 1026


class _Driver:
    """Steps the app while feeding mouse events; optional screenshots by name."""

    def __init__(self, app, mouse, camera, shots: Path | None) -> None:  # type: ignore[no-untyped-def]
        self.app, self.mouse, self.camera, self.shots = app, mouse, camera, shots
        self.pos = (SIZE[0] / 2, SIZE[1] / 2)
        self.pressed = False
        self._render = None

    @property
    def world(self):  # type: ignore[no-untyped-def]
        return self.app.world

    def _event(self, kind: int, pos: tuple[float, float]) -> None:
        ev = SimpleNamespace(
            type=kind, pos=(float(pos[0]), float(pos[1])), button=1, buttons=(1 if self.pressed else 0, 0, 0)
        )
        self.mouse.handle_event(ev, self.camera, SIZE, now=self.world.time)

    def step(self, n: int = 1) -> None:
        for _ in range(n):
            self.app.step()

    def move(self, to: tuple[float, float], frames: int) -> None:
        """Move the cursor in a straight line over ``frames`` steps (one motion event per step)."""
        start = np.array(self.pos)
        for i in range(1, frames + 1):
            p = start + (np.array(to) - start) * i / frames
            self.pos = (float(p[0]), float(p[1]))
            self._event(MOTION, self.pos)
            self.step()

    def path(self, points: list[tuple[float, float]], frames_each: int = 2) -> None:
        for p in points:
            self.move(p, frames_each)

    def press(self) -> None:
        self.pressed = True
        self._event(DOWN, self.pos)
        self.step()

    def release(self) -> None:
        self.pressed = False
        self._event(UP, self.pos)
        self.step()

    def click(self, at: tuple[float, float], travel: int = 12) -> None:
        self.move(at, travel)
        self.press()
        self.step(2)
        self.release()

    def shot(self, name: str) -> None:
        if self.shots is None:
            return
        from engine.render.renderer import Renderer
        from engine.render.scene import RenderScene
        from engine.render.target import make_target
        from games.tasbada.game import GAME

        if self._render is None:
            target = make_target(True, *SIZE)
            self._render = (target, Renderer(target.ctx), RenderScene())
        target, renderer, scene = self._render
        from games.tasbada.quest import Quest
        from games.tasbada.reality import Reality

        self.world.resource(Reality).sprites(self.world.resource(Quest), wait=True)  # the props, built
        scene.clear()
        GAME.draw(self.world, scene, 1.0)
        for line in GAME.status(self.world):
            scene.add_text(line, size=18)
        fb = target.begin()
        renderer.render(scene, self.camera, fb)
        target.end()
        out = target.screenshot(self.shots / f"tasbada_{name}.png")
        print(f"screenshot: {out}")

    def close(self) -> None:
        if self._render is not None:
            self._render[1].release()
            self._render[0].close()


def _px(u: float, v: float) -> tuple[float, float]:
    return (u * SIZE[0], v * SIZE[1])


def _ellipse(cu: float, cv: float, ru: float, rv: float, n: int = 24) -> list[tuple[float, float]]:
    a = np.linspace(0.0, 2.0 * np.pi, n + 1)
    return [_px(cu + ru * np.cos(t), cv + rv * np.sin(t)) for t in a]


def _walk_to(d: _Driver, target: np.ndarray, until, limit: int = 600) -> None:  # type: ignore[no-untyped-def]
    """Drag the held avatar towards floor point ``target`` until ``until()`` or ``limit`` steps."""
    from games.tasbada.objects import avatar_position

    q = d.world.resource(_quest())
    for _ in range(limit):
        if until():
            return
        pos = avatar_position(d.world, q.avatar)
        assert pos is not None
        goal = pos + np.clip(target - pos, -0.35, 0.35)  # the hold point leads the feet by a stride
        px = d.camera.project((goal + np.array([0.0, 0.95, 0.0]))[None], *SIZE)[0]
        d.move((float(px[0]), float(px[1])), 1)
    raise RuntimeError(f"the avatar did not reach {target} in {limit} steps")


def _quest():  # type: ignore[no-untyped-def]
    from games.tasbada.quest import Quest

    return Quest


def _near(d: _Driver, target: np.ndarray, r: float):  # type: ignore[no-untyped-def]
    from games.tasbada.objects import avatar_position

    def ok() -> bool:
        p = avatar_position(d.world, d.world.resource(_quest()).avatar)
        return p is not None and float(np.hypot(*(p - target)[[0, 2]])) < r

    return ok


def journey(d: _Driver) -> Iterator[str]:
    """The demo's moves, yielding each stage name as it is reached."""
    from games.tasbada.objects import layout
    from games.tasbada.quest import Quest

    q: Quest = d.world.resource(Quest)
    d.step(30)
    d.move(_px(0.3, 0.3), 20)
    d.shot("real_start")
    # The clay pot: a box from corner to corner.
    d.move(_px(0.675, 0.845), 15)
    d.press()
    d.move(_px(0.49, 0.52), 30)
    d.release()
    # The plant: a lasso around it.
    ring = _ellipse(0.225, 0.47, 0.145, 0.24)
    d.move(ring[0], 15)
    d.press()
    d.path(ring[1:], 2)
    d.release()
    # The lamp: another box.
    d.move(_px(0.93, 0.665), 15)
    d.press()
    d.move(_px(0.775, 0.095), 25)
    d.release()
    # The floor line: drag its knob down a little, then back onto the skirting.
    from games.tasbada.marking import GROUND_HANDLE_U

    d.move(_px(GROUND_HANDLE_U, q.ground_v), 15)
    d.press()
    d.move(_px(GROUND_HANDLE_U, 0.6), 15)
    d.shot("real")
    d.move(_px(GROUND_HANDLE_U, 0.556), 15)
    d.release()
    yield "real"
    d.click(_px(0.895, 0.07), 20)
    assert q.stage == "props alive", q.stage
    d.step(100)
    d.shot("props_alive")
    for _ in range(5):
        d.step(80)
        d.click(_px(0.3, 0.25), 6)
    yield "props alive"
    d.step(150)
    d.shot("selfie")
    while q.stage != "mixed":
        d.step()
    yield "mixed"
    d.step(50)
    d.shot("mixed_pose")  # the avatar still holds the player's pose
    d.step(10)
    lay = layout(q.ground_v, q.marks)
    start = lay.start + np.array([0.0, 0.95, 0.0])
    px = d.camera.project(start[None], *SIZE)[0]
    d.move((float(px[0]), float(px[1])), 20)
    d.press()
    for i in (1, 0, 2):
        _walk_to(d, lay.cages[i], lambda i=i: q.freed[i] >= 0)
        d.step(10)
    d.shot("mixed")
    d.step(50)
    for i in (0, 4, 3, 2, 1):
        c = lay.crystals[i]
        _walk_to(d, c, lambda i=i: q.crystals[i] >= 0)
    d.shot("mixed_crystals")
    _walk_to(d, lay.gate + np.array([0.0, 0.0, 0.5]), lambda: q.gate_open_t >= 0)
    while q.stage != "virtual":
        d.step()
    d.release()
    yield "virtual"
    d.step(90)
    d.shot("dissolve")
    # Explore: pick the avatar up again and wander to the left.
    pos = d.world.resource(Quest)
    from games.tasbada.objects import avatar_position

    p = avatar_position(d.world, pos.avatar)
    assert p is not None
    px = d.camera.project((p + np.array([0.0, 0.95, 0.0]))[None], *SIZE)[0]
    d.move((float(px[0]), float(px[1])), 10)
    d.press()
    _walk_to(d, np.array([-1.5, 0.0, 1.0]), _near(d, np.array([-1.5, 0.0, 1.0]), 0.3), 400)
    d.release()
    d.step(90)
    d.shot("virtual")


def demo_setup() -> dict[str, object]:
    """The demo's set-up: only the pose found in the shipped selfie (the rest are defaults)."""
    from games.tasbada.game import _selfie_pose
    from games.tasbada.reality import SHIPPED_SELFIE

    points, aspect, note = _selfie_pose(str(SHIPPED_SELFIE), True)
    if points is None:
        raise RuntimeError(f"the demo needs the pose estimator (pip install 'puppetphone[pose]'): {note}")
    return {"pose": points, "pose_aspect": aspect, "pose_note": note}


def make_demo(path: Path = DEMO, shots: Path | None = None, seed: int = 0) -> list[str]:
    """Play the journey and record it to ``path``; returns the stages in the order reached.

    The game is built with a new journey's setup: the shipped photo and selfie, no camera,
    saving nowhere, and the player's pose found in the shipped selfie (recorded in the
    header, so the replay needs no pose estimator) — the demo depends on nothing outside
    the repository.
    """
    from games.tasbada.view import game_camera
    from input.hub import InputHub
    from input.mouse import MouseSource
    from input.recording import Recorder, RecordingHeader
    from puppetphone.games import make_app

    mouse = MouseSource()
    hub = InputHub([mouse]).start()
    setup = demo_setup()
    app = make_app("tasbada", seed, hub, setup)
    header = RecordingHeader(game="tasbada", seed=seed, dt=app.world.dt, sources=["mouse"], setup=setup)
    recorder = Recorder(path, header).attach(app)
    d = _Driver(app, mouse, game_camera(), shots)
    try:
        stages = list(journey(d))
    finally:
        d.close()
        recorder.close()
        hub.close()
    print(f"recorded {recorder.frames} frames to {path}")
    return stages


def main() -> None:
    """Command line: ``--out`` (default the shipped demo) and ``--screenshots DIR``."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", type=Path, default=DEMO)
    ap.add_argument("--screenshots", type=Path, default=None)
    args = ap.parse_args()
    make_demo(args.out, args.screenshots)


if __name__ == "__main__":
    main()
