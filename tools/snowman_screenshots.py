"""Screenshots of each stage of the shipped demo, for the README.

``puppetphone regen screenshots`` replays ``demo.rec`` once and writes a
JPEG the moment each stage is first seen in the world (not at fixed frame numbers,
so a re-recorded demo still gives the right pictures):

- ``rolling`` — the puppet rolls the big ball;
- ``stacking`` — the stick holds a ball high, over another;
- ``carrying`` — the puppet carries the head ball;
- ``alive`` — the first snowman has come alive;
- ``building`` — the snowman rolls a ball of its own;
- ``second`` — the last frame: two snowmen standing.
"""

from __future__ import annotations

import sys
import tempfile
from collections.abc import Callable
from pathlib import Path

from engine.app import App
from engine.components import Stick, Transform
from engine.ecs import World
from engine.ragdoll.components import Prop
from engine.render.renderer import Renderer
from engine.render.scene import RenderScene
from engine.render.target import RenderTarget, make_target
from engine.statemachine import Brain
from games.snowman.components import Snowman
from tools import REPO
from tools.snowman_demo import DEMO_PATH
from games.snowman.game import GAME
from input.hub import InputHub
from input.plugin import input_plugin
from input.recording import read_recording
from input.replay import ReplaySource

__all__ = ["STAGES", "take_screenshots"]

OUT = REPO / "docs" / "screenshots"
DELAY = 45  # frames after a stage is first seen: let it show


def _rolling_big(world: World) -> bool:
    return any(brain.active == "RollSnowball" and not world.has(e, Snowman) and _rolled_radius(world) > 0.3
               for e, brain in world.query(Brain))


def _rolled_radius(world: World) -> float:
    return max((p.radius for _, p in world.query(Prop) if p.carried), default=0.0)


def _lifted_high(world: World) -> bool:
    return any(s.grabbed is not None and world.has(s.grabbed, Prop) and world.get(s.grabbed, Transform).position[1] > 1.0
               for _, s in world.query(Stick))


def _carrying(world: World) -> bool:
    return any(brain.active == "Carry" for _, brain in world.query(Brain))


def _alive(world: World) -> bool:
    return len(world.query(Snowman)) >= 1


def _snowman_rolling(world: World) -> bool:
    return any(brain.active == "RollSnowball" and world.has(e, Snowman) for e, brain in world.query(Brain))


STAGES: dict[str, Callable[[World], bool]] = {
    "rolling": _rolling_big,
    "stacking": _lifted_high,
    "carrying": _carrying,
    "alive": _alive,
    "building": _snowman_rolling,
}


def _save_jpeg(app: App, target: RenderTarget, renderer: Renderer, path: Path) -> None:
    """The game's view with its status lines (the counter), as a JPEG."""
    from PIL import Image

    scene = RenderScene()
    GAME.draw(app.world, scene, 1.0)
    for line in GAME.status(app.world)[:1]:
        scene.add_text(line, color=(0.1, 0.12, 0.18))
    renderer.render(scene, GAME.camera(), target.begin())
    target.end()
    with tempfile.TemporaryDirectory() as tmp:
        png = target.screenshot(Path(tmp) / "frame.png")
        Image.open(png).convert("RGB").save(path, quality=82, optimize=True)
    print(f"{path.name}: frame {app.world.frame}")


def take_screenshots(out: Path = OUT, width: int = 960, height: int = 540) -> list[Path]:
    """Replay the demo and write one JPEG per stage plus the last frame; returns the paths."""
    out.mkdir(parents=True, exist_ok=True)
    rec = read_recording(DEMO_PATH)
    app = App(seed=rec.header.seed)
    app.add_plugin(input_plugin(InputHub(replay=ReplaySource(rec))))
    app.add_plugin(GAME.install)
    target = make_target(True, width, height)
    renderer = Renderer(target.ctx)
    seen: dict[str, int] = {}
    written = []
    try:
        for _ in rec.frames:
            app.step()
            for name, test in STAGES.items():
                if name not in seen and test(app.world):
                    seen[name] = app.world.frame
                if seen.get(name) == app.world.frame - DELAY:
                    written.append(out / f"snowman_{name}.jpg")
                    _save_jpeg(app, target, renderer, written[-1])
        written.append(out / "snowman_second.jpg")
        _save_jpeg(app, target, renderer, written[-1])
    finally:
        target.close()
    missing = sorted(set(STAGES) - set(seen))
    if missing:
        raise RuntimeError(f"the demo never showed: {', '.join(missing)}")
    return written


if __name__ == "__main__":
    take_screenshots(Path(sys.argv[1]) if len(sys.argv) > 1 else OUT)
