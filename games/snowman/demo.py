"""The snowman demo: a scripted mouse plays the whole arc, recorded through the real input path.

Roll three balls, lift the middle one onto the biggest with the stick, carry the
head on top with the puppet: the first snowman comes alive. Then the snowman itself
rolls two balls, carries the smaller onto the bigger, and a second snowman comes
alive. ``python -m games.snowman.demo`` rewrites ``games/snowman/demo.rec``;
``puppetphone play snowman --source replay:demo`` plays it.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from engine.components import Transform
from engine.ecs import Entity, World
from engine.ragdoll.components import Prop
from engine.statemachine import Brain
from games.snowman.components import Snowball, Snowman
from engine.app import App
from input.hub import InputHub
from input.mousebot import MouseBot
from input.plugin import install_input
from input.mouse import MouseSource
from input.recording import Recorder, RecordingHeader

__all__ = ["build_demo", "DEMO_PATH", "DEMO_SEED"]

DEMO_PATH = Path(__file__).with_name("demo.rec")
DEMO_SEED = 2017
P = np.array


def _state(world: World, e: Entity) -> str:
    return world.get(e, Brain).active


def _newest_ball(world: World) -> Entity:
    return max(e for e, _ in world.query(Snowball))


def _ball_near(world: World, point: np.ndarray) -> Entity:
    rows = world.query(Snowball, Transform)
    return min(rows, key=lambda r: float(np.linalg.norm((r[2].position - point)[[0, 2]])))[0]


def build_demo(path: Path = DEMO_PATH, log=print):  # type: ignore[no-untyped-def]
    """Play the scripted session and record it to ``path``; returns the app at the end."""
    from games.snowman.game import GAME

    mouse = MouseSource()
    hub = InputHub([mouse])
    app = App(seed=DEMO_SEED)
    install_input(app, hub)
    GAME.install(app)
    bot = MouseBot(app, mouse, GAME.camera())
    w = app.world
    recorder = Recorder(path, RecordingHeader(game="snowman", seed=DEMO_SEED, dt=w.dt, sources=["mouse"])).attach(app)
    try:
        puppet = next(e for e, _ in w.query(Brain))
        bot.wait(1.0)

        def roll(entity: Entity, path_points: list[np.ndarray], speed: float, notches: int) -> Entity:
            bot.press_on(entity)
            bot.wheel(-notches)
            bot.wait(0.3)
            bot.drag_path(path_points, speed)
            ball = _newest_ball(w)
            bot.wheel(notches)
            bot.wait(0.4)
            bot.release()
            log(f"rolled ball {ball}: r={w.get(ball, Prop).radius:.3f} at {np.round(w.get(ball, Transform).position, 2)}; "
                f"{_state(w, entity)}")
            return ball

        # 1. The big bottom ball, a long loop through fresh snow.
        bottom = roll(puppet, [P([0.0, 0, 1.6]), P([-1.6, 0, 2.6]), P([-3.0, 0, 1.2]), P([-2.6, 0, -0.6]), P([-1.2, 0, -1.4])], 0.75, 4)
        # 2. The middle ball, shorter.
        bot.press_on(puppet)
        bot.drag_path([P([1.0, 0, -1.0])], 1.3)
        bot.release()
        middle = roll(puppet, [P([1.6, 0, 0.6]), P([2.8, 0, 1.6]), P([2.8, 0, 2.6])], 0.75, 4)
        # 3. The head: a short roll.
        bot.press_on(puppet)
        bot.drag_path([P([1.2, 0, 3.6])], 1.3)
        bot.release()
        head = roll(puppet, [P([0.4, 0, 3.0]), P([0.0, 0, 2.4])], 0.75, 4)
        # 4. Lift the middle ball onto the bottom one with the stick.
        bot.press_on(middle)
        bot.wheel(10)
        target = w.get(bottom, Transform).position
        bot.drag_path([P([target[0], 0, target[2]])], 1.5)
        bot.wait(0.3)
        bot.release()
        bot.wait(1.0)
        log(f"middle at {np.round(w.get(middle, Transform).position, 2)}, bottom at {np.round(target, 2)}")
        # 5. The puppet carries the head ball up and puts it on top.
        hp = w.get(head, Transform).position
        bot.press_on(puppet)
        away = hp + (w.get(puppet, Transform).position - hp) * 0.0
        bot.drag_path([P([hp[0], 0, hp[2] + 0.9])], 1.3)
        bot.wheel(-4)
        bot.wait(1.0)
        log(f"over the head ball: {_state(w, puppet)}")
        bot.wheel(4)
        bot.wait(0.5)
        bp = w.get(bottom, Transform).position
        bot.drag_path([P([bp[0], 0, bp[2] + 1.0])], 1.0)
        bot.wait(0.3)
        bot.wheel(-4)
        bot.wait(1.2)
        bot.wheel(4)
        bot.wait(0.5)
        bot.release()
        bot.wait(2.0)
        snowmen = [e for e, _ in w.query(Snowman)]
        log(f"snowmen: {len(snowmen)}; puppet {_state(w, puppet)}; {away}")
        return app
    finally:
        recorder.close()


if __name__ == "__main__":
    build_demo(Path(sys.argv[1]) if len(sys.argv) > 1 else DEMO_PATH)
