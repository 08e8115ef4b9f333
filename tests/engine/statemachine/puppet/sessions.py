"""Recorded puppet sessions: the worlds they run in and the scripts that drive them.

Each session is a short play of the sandbox puppet driven through the *real* input
path — pygame mouse events into :class:`input.mouse.MouseSource` (via
:class:`input.mousebot.MouseBot`), or phone-style ``"device"`` pose samples pushed
into a :class:`input.source.PoseSource` queue — with the hub, the MotionStick and
the brain exactly as in a game. ``python -m tools.regen recordings`` runs the scripts and
writes ``tests/data/<name>.rec``; the tests replay those files through
:func:`make_app` (which must therefore rebuild the very same world) and assert what
the brain did.

This module is loaded by file path (it is test code, not an installed package), so
it imports only the engine, the input layer, the sandbox game and the launcher's ``make_app``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from engine import quat
from engine.app import App
from engine.components import Grabbable, Stick, Transform
from engine.ecs import Entity
from engine.statemachine import Brain
from games.sandbox import GAME
from input.hub import InputHub
from input.motionstick import StickConfig
from input.mouse import MouseSource
from input.mousebot import MouseBot
from input.recording import Recorder, RecordingHeader
from input.sample import PoseSample
from input.source import PoseSource
from puppetphone.games import make_app as games_make_app

__all__ = ["SEED", "SESSIONS", "Session", "make_app", "record", "puppet_of", "PhoneBot", "DATA_DIR"]

SEED = 63
DATA_DIR = Path(__file__).resolve().parents[4] / "tests" / "data"


def make_app(scene: str, hub: InputHub, seed: int = SEED) -> App:
    """The sandbox with its ``scene`` option, built as ``puppetphone replay`` rebuilds it."""
    return games_make_app("sandbox", seed, hub, {"scene": scene})


def puppet_of(app: App) -> Entity:
    """The sandbox's one puppet."""
    return next(e for e, _ in app.world.query(Brain))


# -- a scripted phone ----------------------------------------------------------------
class ScriptedPhone(PoseSource):
    """A 6-DoF phone fed from the test thread (no device thread): ``"device"`` samples."""

    threaded = False

    def __init__(self) -> None:
        super().__init__("phone")
        self._status.connected = True


class PhoneBot:
    """Moves a 6-DoF phone: one ``"device"`` sample per step, pointing the stick at a world point.

    The MotionStick puts an (identity-calibrated) phone at ``StickConfig.virtual_pivot``
    moved by the tracked position; the bot keeps the phone's stick pointing at the
    puppet's hips at grab time and then translates the phone, so the tip follows
    the translation (the stick's length is kept while held).
    """

    def __init__(self, app: App, phone: ScriptedPhone) -> None:
        self.app, self.phone = app, phone
        self.pivot0 = np.array(app.world.resource(StickConfig).virtual_pivot, dtype=np.float64)
        self.position = np.zeros(3)
        self.orientation = quat.identity()

    def _push(self, touch: bool | None = None, calibrate: bool = False) -> None:
        w = self.app.world
        self.phone.push(
            PoseSample(
                time=w.frame * w.dt,
                source="phone",
                orientation=self.orientation,
                position=self.position.copy(),
                touch=touch,
                calibrate=calibrate,
            )
        )

    def step(self, n: int = 1) -> None:
        """Hold the phone where it is for ``n`` steps (one sample each)."""
        for _ in range(n):
            self._push()
            self.app.step()

    def calibrate(self) -> None:
        """Point at the screen (+Z) and calibrate."""
        self.orientation = quat.identity()
        self._push(calibrate=True)
        self.app.step()

    def grab(self, point: np.ndarray) -> None:
        """Point the stick at ``point`` and touch down (grabs what the ray hits)."""
        d = np.asarray(point, dtype=np.float64) - (self.pivot0 + self.position)
        self.orientation = quat.between(np.array([0.0, 0.0, 1.0]), d / np.linalg.norm(d))
        self.step()
        self._push(touch=True)
        self.app.step()

    def move(self, path: Callable[[float], np.ndarray], seconds: float) -> None:
        """Translate the phone along ``path(s)`` (an offset from where it is, ``s`` in [0,1])."""
        start = self.position.copy()
        steps = max(1, int(round(seconds / self.app.world.dt)))
        for k in range(1, steps + 1):
            self.position = start + np.asarray(path(k / steps), dtype=np.float64)
            self._push()
            self.app.step()

    def release(self) -> None:
        """Touch up."""
        self._push(touch=False)
        self.app.step()


# -- scripts -------------------------------------------------------------------------
P = np.array


def _wheel(bot: MouseBot, notches: int, every: int = 6) -> None:
    """Turn the wheel a notch at a time, as a finger does (about ten notches a second).

    A notch changes the grab depth at once; notches on consecutive steps would make
    the filtered tip velocity look like an upward flick (a jump).
    The wheel moves the grab plane along the cursor's ray, which also slides the held
    point over the ground; after each notch the cursor is moved back over the same
    ground point, so only the height changes — what a player keeping the puppet in
    place does.
    """
    ground = bot.tip()
    for _ in range(abs(notches)):
        bot.wheel(int(np.sign(notches)))
        bot.move_to_pixel(bot.pixel(np.array([ground[0], bot.held_height(), ground[2]])), (1, 0, 0))
        bot.step(every - 1)


def _walk_run(app: App, bot: MouseBot) -> None:
    p = puppet_of(app)
    bot.wait(0.3)
    bot.press_on(p)
    bot.wait(0.3)
    bot.drag_path([P([0.0, 0, 1.2])], 0.8)  # walk
    bot.drag_path([P([0.0, 0, 5.2])], 2.6)  # run
    bot.wait(0.8)
    bot.release()
    bot.wait(0.2)


def _crouch_walk(app: App, bot: MouseBot) -> None:
    p = puppet_of(app)
    bot.wait(0.3)
    bot.press_on(p)
    _wheel(bot, -3)
    bot.wait(0.5)
    bot.drag_path([P([0.0, 0, 1.2])], 0.6)
    bot.wait(0.5)
    _wheel(bot, 3)
    bot.wait(0.5)
    bot.release()


def _valid_jump(app: App, bot: MouseBot) -> None:
    p = puppet_of(app)
    bot.wait(0.3)
    bot.press_on(p)
    bot.drag_path([P([0.0, 0, 0.8])], 1.2)
    bot.flick()
    bot.wait(1.2)
    bot.release()
    bot.wait(0.2)


def _turn_in_air(app: App, bot: MouseBot) -> None:
    p = puppet_of(app)
    bot.wait(0.3)
    bot.press_on(p)
    bot.drag_path([P([0.0, 0, 0.8])], 1.2)
    bot.flick()
    bot.wait(0.05)
    tip = bot.tip()
    bot.drag_path([tip + P([1.2, 0, 0])], 4.0)  # a sharp sideways drag while airborne
    bot.wait(0.5)


def _phone_jump(rise: Callable[[float], np.ndarray], seconds: float, after: float) -> Callable[[App, PhoneBot], None]:
    def script(app: App, bot: PhoneBot) -> None:
        p = puppet_of(app)
        bot.step(10)
        bot.calibrate()
        tr = app.world.get(p, Transform)
        bot.grab(app.world.get(p, Grabbable).anchor(tr))
        bot.step(15)
        bot.move(rise, seconds)
        bot.step(int(after / app.world.dt))

    return script


def _arc(height: float, length: float) -> Callable[[float], np.ndarray]:
    return lambda s: P([0.0, 4.0 * height * s * (1.0 - s), length * s])


def _rise_again(s: float) -> np.ndarray:
    """Flung up, part-way down, then up again (a second hop in the air)."""
    if s <= 0.4:
        y = 0.8 * np.sin(0.5 * np.pi * s / 0.4)
    elif s <= 0.7:
        y = 0.8 - 0.35 * 0.5 * (1 - np.cos(np.pi * (s - 0.4) / 0.3))
    else:
        y = 0.45 + 0.35 * 0.5 * (1 - np.cos(np.pi * (s - 0.7) / 0.3))
    return P([0.0, y, 0.8 * s])


def _stop_in_air(s: float) -> np.ndarray:
    """Flung up and forward, then held still high in the air."""
    u = min(s / 0.5, 1.0)
    return P([0.0, 0.9 * np.sin(0.5 * np.pi * u), 0.5 * np.sin(0.5 * np.pi * u)])


def _held_in_air(app: App, bot: MouseBot) -> None:
    p = puppet_of(app)
    bot.wait(0.3)
    bot.press_on(p)
    _wheel(bot, 6)  # lift well above standing height
    bot.wait(0.8)
    bot.drag_path([bot.tip() + P([0.4, 0, 0.3])], 1.0)  # swing it a little
    bot.release()
    bot.wait(6.0)


def _pick_up_carry(app: App, bot: MouseBot) -> None:
    p = puppet_of(app)
    bot.wait(0.3)
    bot.press_on(p)
    bot.drag_path([P([0.0, 0, 0.45])], 0.6)
    _wheel(bot, -3)
    bot.wait(1.6)  # crouched and still over the ball: pick up
    _wheel(bot, 3)
    bot.wait(0.3)
    bot.drag_path([P([0.0, 0, 2.2])], 0.9)  # carry it
    bot.wait(0.6)
    _wheel(bot, -3)  # and put it down
    bot.wait(0.45)
    bot.release()  # and leave it there
    bot.wait(0.3)


def _roll_snowball(app: App, bot: MouseBot) -> None:
    p = puppet_of(app)
    bot.wait(0.3)
    bot.press_on(p)
    _wheel(bot, -3)
    bot.wait(0.4)
    bot.drag_path([P([0.0, 0, 2.4])], 0.7)  # crouch-walk into the big ball and push it
    _wheel(bot, 3)
    bot.wait(0.5)


def _flick_while_rolling(app: App, bot: MouseBot) -> None:
    """A player's report: while rolling a ball, hold and flick the mouse up about 160 px."""
    p = puppet_of(app)
    bot.wait(0.3)
    bot.press_on(p)
    _wheel(bot, -3)
    bot.wait(0.4)
    bot.drag_path([P([0.0, 0, 2.0])], 0.7)  # crouch-walk into the big ball: rolling it
    for _ in range(4):  # 160 px up in four steps, and held up there
        bot.move_to_pixel((bot.pos[0], bot.pos[1] - 40.0), (1, 0, 0))
        bot.step()
    bot.wait(1.0)
    bot.release()
    bot.wait(5.0)


def _deep_crouch_walk(app: App, bot: MouseBot) -> None:
    """A player's report: five wheel-down clicks, then a crouch-walk."""
    p = puppet_of(app)
    bot.wait(0.3)
    bot.press_on(p)
    _wheel(bot, -5)
    bot.wait(0.4)
    bot.drag_path([P([1.2, 0, 1.2])], 0.6)
    bot.wait(0.5)
    _wheel(bot, 5)
    bot.wait(0.5)


@dataclass(frozen=True)
class Session:
    """A recorded session: its world, its controller and its script."""

    name: str
    scene: str
    source: str  # "mouse" or "phone"
    script: Callable[..., None]
    description: str

    @property
    def path(self) -> Path:
        """Where its recording lives."""
        return DATA_DIR / f"puppet_{self.name}.rec"


SESSIONS: dict[str, Session] = {
    s.name: s
    for s in [
        Session(
            "walk_run", "empty", "mouse", _walk_run, "drag slowly then fast: walk then run, speed follows the stick"
        ),
        Session("crouch_walk", "empty", "mouse", _crouch_walk, "wheel down, drag: crouch walk; wheel up: stand"),
        Session("jump_valid", "empty", "mouse", _valid_jump, "flick while walking: anticipation, arc, landing crouch"),
        Session(
            "jump_rise_again",
            "empty",
            "phone",
            _phone_jump(_rise_again, 1.0, 0.4),
            "phone lifted, lowered, lifted again: invalid",
        ),
        Session("jump_turn", "empty", "mouse", _turn_in_air, "flick then drag sideways in the air: invalid"),
        Session(
            "jump_stop",
            "empty",
            "phone",
            _phone_jump(_stop_in_air, 0.8, 0.4),
            "phone lifted and held still in the air: invalid",
        ),
        Session("held_in_air", "empty", "mouse", _held_in_air, "wheel up: held in the air, released, settles, gets up"),
        Session(
            "pick_up_carry", "small_ball", "mouse", _pick_up_carry, "crouch still over a small ball, stand, carry it"
        ),
        Session("roll_snowball", "big_ball", "mouse", _roll_snowball, "crouch-walk into a big ball: roll it"),
        Session(
            "flick_while_rolling",
            "big_ball",
            "mouse",
            _flick_while_rolling,
            "player repro: flick up while rolling a ball; nothing is thrown out of the field",
        ),
        Session(
            "deep_crouch_walk",
            "empty",
            "mouse",
            _deep_crouch_walk,
            "player repro: five wheel-down clicks then a crouch-walk; no ragdoll",
        ),
    ]
}


def record(session: Session, path: Path | None = None) -> App:
    """Run ``session`` through the real input path and record it; returns the app at the end."""
    path = path or session.path
    src: PoseSource = MouseSource() if session.source == "mouse" else ScriptedPhone()
    hub = InputHub([src])
    app = make_app(session.scene, hub)
    header = RecordingHeader(
        game="sandbox",
        seed=SEED,
        dt=app.world.dt,
        sources=[session.source],
        setup={"scene": session.scene},
        extra={"session": session.name},
    )
    with Recorder(path, header).attach(app):
        if session.source == "mouse":
            session.script(app, MouseBot(app, src, GAME.camera()))  # type: ignore[arg-type]
        else:
            session.script(app, PhoneBot(app, src))  # type: ignore[arg-type]
    return app


def stick_of(app: App) -> Stick:
    """The one controller's stick."""
    return next(s for _, s in app.world.query(Stick))
