"""The snowman demo: a scripted mouse plays the whole arc, recorded through the real input path.

Roll three balls, lift the middle one onto the biggest with the stick, let the
puppet carry the head on top: the first snowman comes alive. Then the snowman
itself rolls two balls and lifts the smaller onto the bigger with the stick, and a
second snowman comes alive. ``python -m tools.regen demos`` rewrites
``games/snowman/demo.rec``; ``puppetphone play snowman --source replay:demo``
plays it.

The script only sends mouse events (:class:`input.mousebot.MouseBot`) and reads the
world to aim them, so the recording holds nothing but input and state hashes, and
re-running it after an engine change regenerates a consistent recording. Paths are
planned so the puppet never walks through a ball (it is a kinematic ragdoll and
shoves what it walks into) and everything stays inside the default camera view.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np

import games.snowman
from engine.app import App
from engine.components import Transform
from engine.ecs import Entity, World
from engine.ragdoll.components import Prop
from engine.statemachine import Brain
from games.snowman.components import Snowball, Snowman, SnowmanStats
from input.hub import InputHub
from input.mouse import MouseSource
from input.mousebot import MouseBot
from input.recording import Recorder, RecordingHeader
from puppetphone.games import make_app

__all__ = ["build_demo", "Director", "DEMO_PATH", "DEMO_SEED", "STAGES"]

DEMO_PATH = Path(games.snowman.__file__).with_name("demo.rec")
DEMO_SEED = 2017
#: Named moments of the arc (filled with frame numbers by :func:`build_demo`), for screenshots.
STAGES = ("rolling", "stacking", "alive", "second")

Log = Callable[[str], None]


def _xz(x: float, z: float) -> np.ndarray:
    return np.array([x, 0.0, z])


class Director:
    """Aims the scripted mouse from what the world looks like now."""

    def __init__(self, app: App, bot: MouseBot, log: Log) -> None:
        self.app, self.bot, self.log = app, bot, log
        self.stages: dict[str, int] = {}

    @property
    def world(self) -> World:
        return self.app.world

    def pos(self, e: Entity) -> np.ndarray:
        return self.world.get(e, Transform).position.copy()

    def where(self, e: Entity) -> str:
        """Position for the log, or what became of it (the balls of a snowman are gone)."""
        return str(self.pos(e).round(2)) if self.world.alive(e) else "(part of a snowman now)"

    def state(self, e: Entity) -> str:
        return self.world.get(e, Brain).active

    def mark(self, stage: str) -> None:
        self.stages[stage] = self.world.frame

    def say(self, what: str) -> None:
        self.log(f"[{self.world.frame * self.world.dt:6.2f}s] {what}")

    def balls(self) -> list[Entity]:
        return [e for e, _ in self.world.query(Snowball)]

    def wheel(self, notches: int) -> None:
        """Turn the wheel while holding, keeping the stick tip over the same ground point.

        The mouse lifts and lowers along the ray under the cursor, so a bare wheel
        turn also slides the tip toward or away from the camera and the puppet would
        walk; each notch is paired with a move to where that point now appears.
        """
        hold = self.bot.tip()
        step = self.bot.mouse.wheel_step
        for k in range(abs(notches)):
            target = hold + np.array([0.0, np.sign(notches) * step * (k + 1), 0.0])
            self.bot.move_to_pixel(self.bot.pixel(target), (1, 0, 0))
            self.bot.wheel(int(np.sign(notches)))

    def walk(self, who: Entity, points: list[np.ndarray], speed: float = 1.2) -> None:
        """Grab ``who``, lead it through ``points`` standing, let go once it has arrived."""
        self.bot.press_on(who)
        self.bot.drag_path(points, speed)
        self.bot.wait(0.6)
        self.bot.release()
        self.say(f"{self.world.get(who, Transform).position.round(2)} after walking; {self.state(who)}")

    def roll(self, who: Entity, points: list[np.ndarray], speed: float = 0.8, notches: int = 4) -> Entity:
        """Crouch-walk ``who`` through ``points``: it packs a ball and rolls it; stand up, let go."""
        before = set(self.balls())
        self.bot.press_on(who)
        self.wheel(-notches)
        self.bot.wait(0.4)
        self.bot.drag_path(points, speed)
        self.bot.wait(0.3)
        new = sorted(set(self.balls()) - before)
        if not new:
            raise RuntimeError(f"no ball was started (state {self.state(who)})")
        ball = new[0]
        self.wheel(notches)
        self.bot.wait(0.4)
        self.bot.release()
        self.bot.wait(0.3)
        self.say(
            f"rolled ball {ball}: r={self.world.get(ball, Prop).radius:.3f} at {self.pos(ball).round(2)}; "
            f"{self.state(who)} at {self.pos(who).round(2)}"
        )
        return ball

    def lift_onto(self, ball: Entity, lower: Entity, notches: int) -> None:
        """Grab ``ball`` with the stick, lift it, carry it over ``lower`` and let it down."""
        self.bot.press_on(ball)
        self.wheel(notches)
        self.bot.wait(0.2)
        target = self.pos(lower)
        self.bot.drag_path([target], 1.2)
        self.bot.wait(0.6)
        self.bot.release()
        self.bot.wait(0.8)
        self.say(f"ball {ball} at {self.where(ball)}, on ball {lower} at {self.where(lower)}")

    def approach(self, who: Entity, ball: Entity, side: np.ndarray, gap: float = 0.3) -> None:
        """Walk ``who`` up to ``ball`` from direction ``side`` and stop facing it, ``gap`` from its surface."""
        centre = self.pos(ball)
        centre[1] = 0.0
        side = np.asarray(side, dtype=np.float64) / np.linalg.norm(side)
        r = self.world.get(ball, Prop).radius
        self.walk(who, [centre + side * (r + gap + 0.8), centre + side * (r + gap)], speed=0.9)

    def carry_onto(self, who: Entity, ball: Entity, lower: Entity, notches: int = 4) -> None:
        """``who`` stands behind ``ball`` facing it: pick it up, carry it to ``lower``, put it on top."""
        self.bot.press_on(who)
        self.wheel(-notches)
        self.bot.wait(1.2)
        self.say(f"picking up ball {ball}: {self.state(who)}")
        self.wheel(notches)
        self.bot.wait(0.4)
        here, goal = self.pos(who), self.pos(lower)
        away = here - goal
        away[1] = 0.0
        stand = goal + away / np.linalg.norm(away) * (self.world.get(lower, Prop).radius + 0.45)
        self.bot.drag_path([stand], 0.9)
        self.bot.wait(0.8)
        self.say(f"carrying to {stand.round(2)}: {self.state(who)} at {self.pos(who).round(2)}")
        self.wheel(-notches)
        self.bot.wait(1.2)
        self.say(f"putting down: {self.state(who)}; ball {ball} at {self.where(ball)}")
        self.wheel(notches)
        self.bot.wait(0.5)
        self.bot.release()

    def wait_for_snowman(self, number: int, seconds: float = 3.0) -> Entity:
        """Step until snowman ``number`` is alive."""
        for _ in range(int(seconds / self.world.dt)):
            for e, s in self.world.query(Snowman):
                if s.number == number:
                    self.say(f"snowman {number} is entity {e} at {self.pos(e).round(2)}")
                    return e
            self.bot.step()
        raise RuntimeError(
            f"snowman {number} did not come alive; balls: "
            + ", ".join(f"{b}:{self.pos(b).round(2)} r={self.world.get(b, Prop).radius:.2f}" for b in self.balls())
        )


def _arc(centre: tuple[float, float], radius: float, a0: float, a1: float, n: int) -> list[np.ndarray]:
    """``n`` points on a circle from angle ``a0`` to ``a1`` (radians; 0 = +X, pi/2 = +Z), excluding the start."""
    return [_xz(centre[0] + radius * np.cos(a), centre[1] + radius * np.sin(a)) for a in np.linspace(a0, a1, n + 1)[1:]]


def play(d: Director) -> None:
    """The arc."""
    w = d.world
    puppet = next(e for e, _ in w.query(Brain))
    d.bot.wait(0.5)
    # 1. The head ball first, a short roll south-east (the puppet faces +Z at the start).
    d.mark("rolling")
    head = d.roll(puppet, [_xz(0.0, 1.1)])
    # 2. The bottom ball: three quarters of a loop west, turning gently (a ball swung
    #    round fast in front of the puppet bumps into it).
    d.walk(puppet, [_xz(-0.3, 0.2), _xz(-0.2, -0.4), _xz(0.0, -0.4)])
    bottom = d.roll(puppet, _arc((-1.5, -0.4), 1.5, -0.5 * np.pi, np.pi, 12))
    # 3. The middle ball, east; walk round the bottom ball and face the way to roll first.
    here = d.pos(puppet)
    d.walk(puppet, [here + _xz(0.0, 0.6), _xz(-0.3, 0.6), _xz(0.7, -0.3), _xz(1.1, -0.6)])
    middle = d.roll(puppet, [_xz(2.4, -0.6), _xz(2.9, 0.0), _xz(3.0, 0.8)])
    # 4. The stick lifts the middle ball onto the bottom one.
    d.mark("stacking")
    d.lift_onto(middle, bottom, 10)
    # 5. The puppet walks up to the head ball, carries it up and puts it on top.
    d.approach(puppet, head, _xz(1.0, 0.0), gap=0.4)
    d.carry_onto(puppet, head, bottom)
    first = d.wait_for_snowman(1)
    d.mark("alive")
    d.bot.wait(0.5)
    # The puppet steps aside (it stands between the camera and the snowman).
    d.walk(puppet, [d.pos(puppet) + _xz(0.6, -0.6), _xz(-1.0, -2.6)])
    # 6. The snowman builds another snowman: a bottom ball and a head ball, stacked with the stick.
    here = d.pos(first)
    d.walk(first, [here + _xz(0.6, 0.3), _xz(0.2, -1.2), _xz(0.8, -1.2)])
    bottom2 = d.roll(first, _arc((2.0, 0.3), 1.5, -0.5 * np.pi, 0.5 * np.pi, 10))
    d.walk(first, [d.pos(first) + _xz(0.0, 0.6), _xz(3.0, 1.6), _xz(3.6, -0.4), _xz(3.6, -1.6), _xz(3.1, -1.6)])
    head2 = d.roll(first, [_xz(1.9, -1.6)])
    d.mark("second")
    d.lift_onto(head2, bottom2, 8)
    d.wait_for_snowman(2)
    d.bot.wait(1.5)
    stats = w.resource(SnowmanStats)
    d.say(
        f"done: {stats.built} snowmen built, {stats.balls_started} balls started; "
        + ", ".join(f"{e}: {d.state(e)} at {d.pos(e).round(2)}" for e, _ in w.query(Brain))
    )


def build_demo(path: Path = DEMO_PATH, log: Log = print) -> tuple[App, dict[str, int]]:
    """Play the scripted session and record it to ``path``; returns the app and the stage frames."""
    from games.snowman.game import GAME

    mouse = MouseSource()
    hub = InputHub([mouse])
    app = make_app("snowman", DEMO_SEED, hub, {})  # a fresh field, saving nowhere
    bot = MouseBot(app, mouse, GAME.camera())
    header = RecordingHeader(game="snowman", seed=DEMO_SEED, dt=app.world.dt, sources=["mouse"], setup={})
    recorder = Recorder(path, header).attach(app)
    director = Director(app, bot, log)
    try:
        play(director)
    finally:
        recorder.close()
    log(
        f"recorded {app.world.frame} frames ({app.world.frame * app.world.dt:.1f} s) to {path}; stages {director.stages}"
    )
    return app, director.stages


if __name__ == "__main__":
    build_demo(Path(sys.argv[1]) if len(sys.argv) > 1 else DEMO_PATH)
