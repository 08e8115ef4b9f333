"""Screenshots of each stage of the shipped demo, for the README.

``python -m tools.regen screenshots`` replays ``demo.rec`` once and writes a
JPEG the moment each stage is first seen in the world (not at fixed frame numbers,
so a re-recorded demo still gives the right pictures):

- ``rolling`` — the puppet rolls the big ball;
- ``stacking`` — the stick holds a ball high, over another;
- ``carrying`` — the puppet carries the head ball;
- ``alive`` — the first snowman has come alive;
- ``building`` — the snowman rolls a ball of its own;
- ``second`` — the last frame: two snowmen standing;
- ``field`` — the same moment from lower down: the conifers, the tracks and footprints,
  the horizon.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np

from authoring.session import Session
from engine.camera import OrbitCamera
from engine.components import Stick, Transform
from engine.ecs import World
from engine.ragdoll.components import Prop
from engine.render.scene import RenderScene
from engine.render.target import save_image
from engine.runner import Runner, RunOptions
from engine.statemachine import Brain
from engine.statemachine.puppet import PuppetState
from games.snowman.components import Snowman
from games.snowman.game import GAME
from input.hub import InputHub
from input.recording import read_recording
from input.replay import ReplaySource
from puppetphone.session import build_activity
from tools import REPO
from tools.snowman_demo import DEMO_PATH

__all__ = ["STAGES", "take_screenshots"]

OUT = REPO / "docs" / "screenshots"
DELAY = 45  # frames after a stage is first seen: let it show
FIELD_CAMERA = OrbitCamera(target=np.array([0.0, 0.9, 0.0]), yaw=0.15, pitch=0.15, distance=10.5)
"""Low over the field, so the far ridge and the sky show above the snow."""


def _rolling_big(world: World) -> bool:
    return any(
        brain.active == PuppetState.ROLL_SNOWBALL and not world.has(e, Snowman) and _rolled_radius(world) > 0.3
        for e, brain in world.query(Brain)
    )


def _rolled_radius(world: World) -> float:
    return max((p.radius for _, p in world.query(Prop) if p.carried), default=0.0)


def _lifted_high(world: World) -> bool:
    return any(
        s.grabbed is not None and world.has(s.grabbed, Prop) and world.get(s.grabbed, Transform).position[1] > 1.0
        for _, s in world.query(Stick)
    )


def _carrying(world: World) -> bool:
    return any(brain.active == PuppetState.CARRY for _, brain in world.query(Brain))


def _alive(world: World) -> bool:
    return len(world.query(Snowman)) >= 1


def _snowman_rolling(world: World) -> bool:
    return any(brain.active == PuppetState.ROLL_SNOWBALL and world.has(e, Snowman) for e, brain in world.query(Brain))


STAGES: dict[str, Callable[[World], bool]] = {
    "rolling": _rolling_big,
    "stacking": _lifted_high,
    "carrying": _carrying,
    "alive": _alive,
    "building": _snowman_rolling,
}


class _DemoView:
    """The replayed demo as the runner's activity, drawn as the README shows it: the game's
    view and its first status line (the counter), without the overlay's help and sources."""

    def __init__(self, activity: Session) -> None:
        self.activity, self.app = activity, activity.simulation.app
        self.dt, self.camera = activity.dt, GAME.camera()

    def step(self) -> None:
        self.activity.step()

    def finished(self) -> bool:
        return self.activity.finished()

    def draw(self, scene: RenderScene, alpha: float, size: tuple[int, int]) -> None:
        GAME.draw(self.app.world, scene, 1.0)
        for line in GAME.status(self.app.world)[:1]:
            scene.add_text(line, color=(0.1, 0.12, 0.18))


def _save_jpeg(runner: Runner, view: _DemoView, path: Path) -> None:
    runner.draw(view)
    save_image(runner.viewer.read_pixels(), path)
    print(f"{path.name}: frame {view.app.world.frame}")


def take_screenshots(out: Path = OUT, width: int = 960, height: int = 540) -> list[Path]:
    """Replay the demo through the runner and write one JPEG per stage, the last frame and the field view."""
    out.mkdir(parents=True, exist_ok=True)
    rec = read_recording(DEMO_PATH)
    activity = build_activity(
        "snowman",
        rec.header.seed,
        InputHub(replay=ReplaySource(rec)),
        setup=GAME.replay_setup(rec.header.setup),
        verify=rec,
    )
    view = _DemoView(activity)
    runner = Runner(RunOptions(headless=True, width=width, height=height))
    seen: dict[str, int] = {}
    written: list[Path] = []

    def watch(world: World) -> None:
        for name, test in STAGES.items():
            if name not in seen and test(world):
                seen[name] = world.frame
            if seen.get(name) == world.frame - DELAY:
                written.append(out / f"snowman_{name}.jpg")
                _save_jpeg(runner, view, written[-1])

    activity.simulation.app.on_step_end.append(watch)
    try:
        runner.run(view)
        written.append(out / "snowman_second.jpg")
        _save_jpeg(runner, view, written[-1])
        view.camera = FIELD_CAMERA
        written.append(out / "snowman_field.jpg")
        _save_jpeg(runner, view, written[-1])
    finally:
        runner.close()
    assert activity.check is not None
    if not activity.check.ok:
        raise RuntimeError(f"the demo no longer replays: {activity.check.message()}")
    missing = sorted(set(STAGES) - set(seen))
    if missing:
        raise RuntimeError(f"the demo never showed: {', '.join(missing)}")
    return written


if __name__ == "__main__":
    take_screenshots(Path(sys.argv[1]) if len(sys.argv) > 1 else OUT)
