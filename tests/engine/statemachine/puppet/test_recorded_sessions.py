"""The puppet brain as deterministic replays of recorded input.

Each ``tests/data/puppet_*.rec`` is a real session through the real input path
(mouse events or phone samples → hub → MotionStick → brain), recorded by
``python -m tools.regen recordings``. Every test replays its file through
:func:`input.replay.verify` — which rebuilds the world and checks every step's
state hash — while watching the puppet, then asserts the state sequence from the
brain's trace and the quantities that make each behaviour what it is, and what the
overlay says the puppet is doing (:mod:`engine.statemachine.puppet.words`).

When an engine change legitimately alters the simulation the hashes stop matching:
re-record with ``python -m tools.regen recordings`` and re-run.
"""

from __future__ import annotations

import importlib.util
import sys
from dataclasses import dataclass, field, replace
from itertools import groupby
from pathlib import Path

import numpy as np
import pytest

from engine.components import LocalPose, Stick, Transform
from engine.ragdoll.components import Prop, Ragdoll
from engine.statemachine import Brain
from engine.statemachine.puppet import Jumping, PuppetBody
from engine.statemachine.puppet.words import describe_puppet
from games.sandbox import BIG_BALL, GAME
from input.hub import InputHub
from input.mouse import MouseSource
from input.mousebot import MouseBot
from input.recording import read_recording
from input.replay import verify

_spec = importlib.util.spec_from_file_location("puppet_sessions", Path(__file__).with_name("sessions.py"))
assert _spec is not None and _spec.loader is not None
S = importlib.util.module_from_spec(_spec)
sys.modules[_spec.name] = S
_spec.loader.exec_module(S)

DT = 1.0 / 60.0
STAND = 0.95


@dataclass
class Watch:
    """Per replayed step: what the tests look at."""

    state: list[str] = field(default_factory=list)
    phase: list[str] = field(default_factory=list)
    pos: list[np.ndarray] = field(default_factory=list)
    hips: list[float] = field(default_factory=list)
    stick_speed: list[float] = field(default_factory=list)
    target_height: list[float] = field(default_factory=list)
    held: list[bool] = field(default_factory=list)
    flick: list[bool] = field(default_factory=list)
    settled: list[bool] = field(default_factory=list)
    ball: list[np.ndarray] = field(default_factory=list)
    ball_rot: list[np.ndarray] = field(default_factory=list)
    words: list[str] = field(default_factory=list)
    trace: list = field(default_factory=list)  # type: ignore[type-arg]
    jump: Jumping = field(default_factory=Jumping)
    frames: int = 0

    def arr(self, name: str) -> np.ndarray:
        return np.array(getattr(self, name))

    def first(self, name: str, value: object) -> int:
        return next(i for i, v in enumerate(getattr(self, name)) if v == value)


_CACHE: dict[str, Watch] = {}


def replay(name: str) -> Watch:
    """Replay a session's recording, asserting every state hash; what happened, step by step."""
    if name in _CACHE:
        return _CACHE[name]
    session = S.SESSIONS[name]
    if not session.path.exists():
        pytest.fail(f"{session.path} is missing: run python -m tools.regen recordings")
    rec = read_recording(session.path)
    assert rec.complete, rec.problem
    assert rec.header.extra["session"] == name and rec.header.sources == [session.source]
    w = Watch()

    def on_step(app, i):  # type: ignore[no-untyped-def]
        world = app.world
        p = S.puppet_of(app)
        brain, body = world.get(p, Brain), world.get(p, PuppetBody)
        stick = next(s for _, s in world.query(Stick))
        w.state.append(brain.active)
        w.phase.append(world.get(p, Jumping).phase.value)
        w.pos.append(world.get(p, Transform).position.copy())
        w.hips.append(float(world.get(p, LocalPose).root[1]))
        w.stick_speed.append(float(np.hypot(stick.velocity[0], stick.velocity[2])))
        w.target_height.append(body.target_height)
        w.held.append(stick.grabbed == p)
        w.flick.append(bool(stick.flick))
        w.settled.append(bool(world.get(p, Ragdoll).settled))
        balls = world.query(Prop, Transform)
        if balls:
            w.ball.append(balls[0][2].position.copy())
            w.ball_rot.append(balls[0][2].rotation.copy())
        w.words.append(describe_puppet(world, p, brain))
        w.trace, w.jump = list(brain.trace), replace(world.get(p, Jumping))

    result = verify(lambda hub: S.make_app(session.scene, hub), rec, on_step=on_step)
    assert result.ok, result.message()
    assert result.matched == len(rec.frames) > 0
    w.frames = result.frames
    _CACHE[name] = w
    return w


def transitions(w: Watch) -> list[tuple[str, str, str]]:
    return [(t.source, t.target, t.reason) for t in w.trace]


def ground_speed(w: Watch) -> np.ndarray:
    """The puppet's measured ground speed per step (central to the recorded motion, not the request)."""
    pos = w.arr("pos")
    d = np.linalg.norm(np.diff(pos[:, [0, 2]], axis=0), axis=1) / DT
    return np.concatenate([[0.0], d])


# -- (1) walk then run ----------------------------------------------------------------
def test_walk_then_run_speed_follows_the_stick() -> None:
    w = replay("walk_run")
    assert transitions(w) == [("-", "Locomotion", "start")]
    speed, stick = ground_speed(w), w.arr("stick_speed")
    held = w.arr("held")
    walk = held & (np.abs(stick - 0.8) < 0.04)
    run = held & (np.abs(stick - 2.6) < 0.1)
    assert walk.sum() >= 30 and run.sum() >= 30
    walk_speed, run_speed = float(speed[walk].mean()), float(speed[run].mean())
    # The puppet's own speed tracks the stick's (plus a small catch-up term).
    assert walk_speed == pytest.approx(0.8, rel=0.25)
    assert run_speed == pytest.approx(2.6, rel=0.2)
    assert run_speed > 2.5 * walk_speed
    # And it ends where it was led: the stick stopped at z = 5.2.
    assert w.pos[-1][2] == pytest.approx(5.2, abs=0.35)


# -- (2) crouch walk ------------------------------------------------------------------
def test_crouch_walk_lowers_the_hips_and_walks() -> None:
    w = replay("crouch_walk")
    assert transitions(w) == [
        ("-", "Locomotion", "start"),
        ("Locomotion", "Crouch", "lowered"),
        ("Crouch", "Locomotion", "raised"),
    ]
    state, hips = w.state, w.arr("hips")
    crouch = np.array([s == "Crouch" for s in state])
    assert hips[:15].min() > 0.9  # standing before the wheel turns
    # Three wheel notches hold the hips 0.3 m lower: the crouch follows them down.
    low = crouch & (w.arr("target_height") < 0.7)
    assert low.sum() > 60
    assert float(np.median(hips[low])) == pytest.approx(0.65, abs=0.06)
    # It walked while crouched: about the 1.2 m it was led.
    pos = w.arr("pos")
    moved = float(np.linalg.norm((pos[crouch][-1] - pos[crouch][0])[[0, 2]]))
    assert moved == pytest.approx(1.2, abs=0.3)
    assert ground_speed(w)[crouch].max() > 0.4
    assert hips[-1] > 0.88  # stood up again


# -- (3) a valid jump -----------------------------------------------------------------
def test_valid_jump_anticipates_reaches_its_apex_and_lands() -> None:
    w = replay("jump_valid")
    assert transitions(w) == [
        ("-", "Locomotion", "start"),
        ("Locomotion", "Jump", "flick"),
        ("Jump", "Land", "landed"),
        ("Land", "Locomotion", "absorbed"),
    ]
    flick = w.first("flick", True)
    jump = w.first("state", "Jump")
    take_off = w.first("phase", "air")
    assert jump == flick  # the flick starts the jump on its own step
    # The anticipation squat: a forced delay of 0.16 s before leaving the ground.
    assert take_off - flick == pytest.approx(0.16 / DT, abs=1)
    hips = w.arr("hips")
    assert hips[flick:take_off].min() < 0.8
    pos = w.arr("pos")
    assert np.all(pos[:take_off, 1] == 0.0)
    # Ballistic launch at 3.4 m/s: apex 3.4² / 2g above standing.
    expected_apex = STAND + 3.4**2 / (2 * 9.81)
    assert w.jump.apex_height == pytest.approx(expected_apex, abs=0.03)
    assert pos[:, 1].max() + STAND == pytest.approx(expected_apex, abs=0.05)
    # It carried its walking momentum forward (+Z), not the flick's stroke.
    land = w.first("state", "Land")
    assert pos[land][2] - pos[take_off][2] > 0.4
    assert abs(pos[land][0] - pos[take_off][0]) < 0.1
    assert pos[land][1] == 0.0
    # Landing crouch: the hips dip and come back before Locomotion resumes.
    back = land + w.state[land:].index("Locomotion")
    assert hips[land:back].min() < 0.8
    assert (back - land) * DT == pytest.approx(0.22, abs=2 * DT)
    assert "Ragdoll" not in w.state


# -- (4-6) invalid jumps --------------------------------------------------------------
@pytest.mark.parametrize(
    "name, reason",
    [
        ("jump_rise_again", "rose again after starting to fall"),
        ("jump_turn", "turned in the air"),
        ("jump_stop", "stopped in the air"),
    ],
)
def test_invalid_jump_ends_in_ragdoll(name: str, reason: str) -> None:
    w = replay(name)
    assert transitions(w) == [
        ("-", "Locomotion", "start"),
        ("Locomotion", "Jump", "flick"),
        ("Jump", "Ragdoll", "jump_invalid"),
    ]
    assert w.jump.invalid is not None and w.jump.invalid.value == reason
    take_off = w.first("phase", "air")
    fell = w.first("state", "Ragdoll")
    assert take_off < fell  # invalid in the air, not on the ground
    assert all(s == "Ragdoll" for s in w.state[fell:])
    assert max(p[1] for p in w.pos[take_off:fell]) > 0.15  # it really was airborne


def test_phone_jumps_ride_the_stick_and_the_mouse_jump_is_ballistic() -> None:
    for name in ("jump_rise_again", "jump_stop"):
        w = replay(name)
        take_off = w.first("phase", "air")
        fell = w.first("state", "Ragdoll")
        # Riding the phone: the hips are where the stick holds them.
        th = w.arr("target_height")[take_off + 1 : fell]
        hips = w.arr("pos")[take_off + 1 : fell, 1] + STAND
        assert np.allclose(hips, th, atol=1e-9)


# -- (7) held in the air --------------------------------------------------------------
def test_held_in_the_air_falls_settles_and_gets_up() -> None:
    w = replay("held_in_air")
    assert transitions(w) == [
        ("-", "Locomotion", "start"),
        ("Locomotion", "Ragdoll", "no state fits"),
        ("Ragdoll", "GetUp", "settled"),
        ("GetUp", "Locomotion", "standing"),
    ]
    fell = w.first("state", "Ragdoll")
    assert w.held[fell] and w.target_height[fell] > STAND + 0.25
    released = fell + w.held[fell:].index(False)
    getup = w.first("state", "GetUp")
    assert released < getup
    assert w.settled[getup - 1]  # at rest before getting up
    # It hung from the stick while held: the hips well above standing height.
    assert max(w.hips[fell:released]) > STAND + 0.2
    standing = getup + w.state[getup:].index("Locomotion")
    assert 0.5 < (standing - getup) * DT < 4.0
    assert w.hips[-1] == pytest.approx(STAND, abs=0.06)
    assert w.state[-1] == "Locomotion"


# -- (8) pick up and carry ------------------------------------------------------------
def test_pick_up_carry_and_put_down() -> None:
    w = replay("pick_up_carry")
    seq = [t[1] for t in transitions(w)]
    assert seq[:6] == ["Locomotion", "Crouch", "PickUp", "Carry", "PutDown", "Locomotion"]
    assert "RollSnowball" not in seq
    ball = w.arr("ball")
    pick, carry, put = w.first("state", "PickUp"), w.first("state", "Carry"), w.first("state", "PutDown")
    assert ball[:pick, 1] == pytest.approx(0.14, abs=0.01)  # resting on the ground
    assert float(ground_speed(w)[pick - 10 : pick].mean()) < 0.2  # still when it reached
    carried = ball[carry + 30 : put]
    assert carried[:, 1].min() > 0.9  # in front of the chest
    pos = w.arr("pos")
    gap = np.linalg.norm((carried - pos[carry + 30 : put])[:, [0, 2]], axis=1)
    assert gap == pytest.approx(0.22 + 0.14, abs=0.02)  # kept in front of the puppet
    assert np.linalg.norm((ball[put] - ball[carry])[[0, 2]]) > 1.0  # carried along
    assert ball[-1][1] == pytest.approx(0.14, abs=0.02)  # set down on the ground
    assert ball[-1][2] > pos[-1][2]  # in front of the puppet


# -- (9) roll a snowball --------------------------------------------------------------
def test_crouch_walking_into_a_big_ball_rolls_it() -> None:
    w = replay("roll_snowball")
    assert transitions(w) == [
        ("-", "Locomotion", "start"),
        ("Locomotion", "Crouch", "lowered"),
        ("Crouch", "RollSnowball", "pushes a ball"),
        ("RollSnowball", "Locomotion", "stood up"),
    ]
    ball, rot = w.arr("ball"), w.arr("ball_rot")
    start = w.first("state", "RollSnowball")
    stop = start + w.state[start:].index("Locomotion")
    assert np.allclose(ball[:start, [0, 2]], BIG_BALL[[0, 2]], atol=0.02)  # at rest until pushed
    travelled = float(np.linalg.norm((ball[stop] - ball[start])[[0, 2]]))
    assert travelled > 0.5
    assert np.allclose(ball[start:stop, 1], 0.3, atol=1e-9)  # on the ground
    # Rolling without slipping: each step turns it by distance / radius.
    step = np.linalg.norm(np.diff(ball[start:stop, :], axis=0)[:, [0, 2]], axis=1)
    dots = np.abs(np.einsum("ij,ij->i", rot[start : stop - 1], rot[start + 1 : stop]))
    turned = 2 * np.arccos(np.clip(dots, -1.0, 1.0))
    assert np.allclose(turned, step / 0.3, atol=1e-4)
    # Pushed ahead of the puppet, crouched.
    pos = w.arr("pos")
    assert np.all(ball[start + 1 : stop, 2] > pos[start + 1 : stop, 2] + 0.3)
    hips = w.arr("hips")
    assert float(np.median(hips[start:stop])) < 0.75


# -- (10) what the overlay says ---------------------------------------------------------
def words_along(name: str) -> list[str]:
    """The puppet's words (:func:`describe_puppet`) per replayed step, repeats collapsed."""
    return [w for w, _ in groupby(replay(name).words)]


def in_order(words: list[str], expected: list[str]) -> bool:
    """Whether ``expected`` occur in ``words`` in this order (others may come between)."""
    it = iter(words)
    return all(any(w == e for w in it) for e in expected)


@pytest.mark.parametrize(
    "name,expected",
    [
        ("walk_run", ["standing", "walking", "running"]),
        ("crouch_walk", ["crouching", "crouch-walking"]),
        ("roll_snowball", ["rolling a snowball"]),
        ("pick_up_carry", ["picking up a ball", "carrying a ball"]),
        ("jump_valid", ["getting ready to jump", "in the air", "landing"]),
        ("held_in_air", ["hanging from the stick", "fell over", "getting up", "standing"]),
    ],
)
def test_sessions_read_in_a_players_words(name: str, expected: list[str]) -> None:
    words = words_along(name)
    assert in_order(words, expected), words
    assert not any(w[:1].isupper() for w in words)  # no state names ("Locomotion") leak through


@pytest.mark.parametrize("name,why", [("jump_turn", "turned in the air"), ("jump_stop", "stopped in the air")])
def test_an_invalid_jump_says_why(name: str, why: str) -> None:
    words = words_along(name)
    assert in_order(words, ["in the air", f"fell: invalid jump ({why})"]), words
    assert words[-1] == f"fell: invalid jump ({why})"  # still held up by the stick: the reason stays


def test_the_reason_of_a_fall_goes_once_the_puppet_is_up() -> None:
    """Played live (the recording ends while the stick still holds the puppet): let go, watch it get up."""
    hub = InputHub([mouse := MouseSource()])
    app = S.make_app("empty", hub)
    bot = MouseBot(app, mouse, GAME.camera())
    S.SESSIONS["jump_turn"].script(app, bot)
    p = S.puppet_of(app)
    brain = app.world.get(p, Brain)
    assert describe_puppet(app.world, p, brain) == "fell: invalid jump (turned in the air)"
    bot.release()
    seen = []
    for _ in range(int(8.0 / app.world.dt)):
        bot.step()
        seen.append(describe_puppet(app.world, p, brain))
    words = [w for w, _ in groupby(seen)]
    assert in_order(words, ["getting up", "standing"]), words
    assert not any("invalid" in w for w in words[words.index("getting up") :]), words
    assert words[-1] == "standing"


# -- players' reports of physics that broke (issue: physics that no input can break) -------------
def test_a_flick_while_rolling_a_ball_throws_nothing_out_of_the_field():
    """Reported: "Ragdoll (jump_invalid)", a MuJoCo QACC warning, puppet and balls thrown out of view for
    ~30 s. Then: the invalid jump dropped the puppet, but everything stayed near. Now the mouse's upward
    stroke is a gesture that does not drag the stick toward the horizon, so the rolling puppet is not
    yanked at all: it stands up where the cursor is then held and stays on its feet."""
    w = replay("flick_while_rolling")
    states = [t.target for t in w.trace]
    assert "RollSnowball" in states and "Ragdoll" not in states
    assert states[-1] == "Locomotion"
    pos, ball = w.arr("pos"), w.arr("ball")
    assert np.isfinite(pos).all() and np.isfinite(ball).all()
    assert np.abs(pos[:, [0, 2]]).max() < 4.0 and pos[:, 1].max() < 0.01  # on its feet, near
    rolled = w.first("state", "RollSnowball")
    speed = np.linalg.norm(np.diff(ball[rolled:], axis=0), axis=1) * 60
    assert speed.max() < 3.0 and ball[rolled:, 1].max() < 0.5  # m/s, m: the ball is pushed on, never flung


def test_five_wheel_clicks_then_a_crouch_walk_stays_on_its_feet():
    """Reported: the puppet dropped into a ragdoll dragged over the ground."""
    w = replay("deep_crouch_walk")
    assert "Ragdoll" not in w.state
    assert "Crouch" in w.state and w.state[-1] == "Locomotion"
    moved = np.linalg.norm(w.arr("pos")[-1][[0, 2]] - w.arr("pos")[0][[0, 2]])
    assert moved > 1.0  # it crouch-walked where it was dragged
