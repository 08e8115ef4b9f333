"""The puppet in play, driven through the real input path and measured as an onlooker would.

A *case* is a path of the stick's ground point over time (a straight drag, a circle,
stop-and-go, a zigzag, a reversal). :func:`drive` plays it in the sandbox with a
scripted controller that produces what the real device produces — a 6-DoF phone's
``"device"`` samples, or the mouse's pygame events through :class:`input.mouse.MouseSource`
— at the device's own rate (120 Hz: two samples per 60 Hz step, each with its event
time), so the hub, the MotionStick, the state machine, the blend, the leg IK and FK all
run as in ``play``. Per step it records the toe tips and heels of both feet after IK,
the puppet's ground position and its state.

:func:`motion_figures` turns that into the figures ``bench motion`` prints:

- planted-foot slide: a foot is planted while its toe tip is within 3 cm of its lowest
  height in the measured window for two steps; its horizontal speed then, mean and
  95th percentile (m/s);
- the lowest sole point (toe tip or heel) over the whole case (m; below 0 is in the floor);
- the time to 90 % of the stick's speed after a start (s), and the time to come to rest
  after the stick stops (s);
- whether the puppet fell (entered the ragdoll).

:func:`blend_alone_slide` is the baseline: the blend the lookup table picks for the same
speed, played alone (no input, no control, no IK) and measured the same way.
:func:`jump` flicks from a walk or run and reports how the jump went.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
import pygame

from engine import quat
from engine.app import App
from engine.blend.locomotion import LocomotionPlayer
from engine.clips.contacts import HEEL_OFFSET
from engine.components import Grabbable, Puppet, Stick, Transform, WorldPose
from engine.statemachine import Brain
from engine.statemachine.puppet.body import Jumping, PuppetBody
from engine.statemachine.puppet.names import PuppetState
from input.hub import InputHub
from input.motionstick import StickConfig
from input.mouse import MouseSource
from input.sample import PoseSample
from input.source import PoseSource

__all__ = [
    "Case",
    "CASES",
    "straight",
    "Run",
    "drive",
    "motion_figures",
    "MotionFigures",
    "blend_alone_slide",
    "JumpResult",
    "jump",
    "DEVICES",
    "CONTROLLERS",
]

from engine.arrays import F64 as F

DEVICES = ("phone", "mouse")
CONTROLLERS = ("spring", "legacy")
RATE = 120.0  # device samples per second (a 125 Hz mouse, a 100-120 Hz phone)
_WAY = np.array([0.6, -0.8])  # across the sandbox camera's view, as clip_walk walks
_SIDE = np.array([0.8, 0.6])


@dataclass(frozen=True)
class Case:
    """A stick path: ``path(t)`` is the ground offset (x, z) from the puppet's start at ``t`` s.

    ``moving`` is when the stick moves; ``measure`` the window (s) whose feet are judged;
    ``speed`` the stick's steady speed (m/s) when it has one (straight drags), for the
    time to 90 % and the blend-alone baseline."""

    name: str
    path: Callable[[float], F]
    moving: float
    measure: tuple[float, float]
    speed: float | None = None


def straight(speed: float) -> Case:
    """A straight drag at ``speed`` m/s for about 6 m (at least 1.6 s), then a stop."""
    seconds = max(6.0 / speed, 1.6) if speed >= 1.0 else min(6.0 / speed, 8.0)
    return Case(f"straight_{speed:g}", lambda t: _WAY * speed * min(t, seconds), seconds, (0.6, seconds), speed)


def _circle(t: float, radius: float = 1.5, speed: float = 1.5) -> F:
    a = speed * t / radius
    centre = _SIDE * radius
    return centre - _SIDE * radius * np.cos(a) + _WAY * radius * np.sin(a)


def _stop_and_go(t: float) -> F:
    """1.2 m/s for 1.5 s, stand 1 s, and again, twice."""
    legs = [(0.0, 1.5, True), (1.5, 2.5, False), (2.5, 4.0, True), (4.0, 5.0, False), (5.0, 6.5, True)]
    moved = sum(min(max(t - a, 0.0), b - a) for a, b, go in legs if go)
    return _WAY * 1.2 * moved


def _zigzag(t: float) -> F:
    """1.3 m/s forward, swinging 0.6 m to each side every 1.2 s."""
    return _WAY * 1.3 * t + _SIDE * 0.6 * np.sin(2 * np.pi * t / 2.4)


def _reversal(t: float) -> F:
    """1.2 m/s out for 2 s, then straight back."""
    return _WAY * 1.2 * (t if t <= 2.0 else max(4.0 - t, 0.0))


CASES: tuple[Case, ...] = (
    *(straight(v) for v in (0.3, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0)),
    Case("circle_r1.5", _circle, 6.0, (1.0, 6.0)),
    Case("stop_and_go", _stop_and_go, 6.5, (0.6, 6.5)),
    Case("zigzag", _zigzag, 5.0, (0.6, 5.0)),
    Case("reversal", _reversal, 4.0, (0.6, 4.0)),
)


@dataclass
class Run:
    """What one driven case recorded, per step from the drag's start."""

    dt: float
    toes: F  # [T, 2, 3]
    heels: F  # [T, 2, 3]
    position: F  # [T, 3]
    states: list[str]
    jumps: list[Jumping]


class _Phone(PoseSource):
    """A 6-DoF phone fed from this thread (no device thread): ``"device"`` samples."""

    threaded = False

    def __init__(self) -> None:
        super().__init__("phone")
        self._status.connected = True


class _Driver:
    """The sandbox with one puppet and one scripted device, stepping and recording."""

    def __init__(
        self, device: str, controller: str, seed: int = 0, fps: float = 60.0, character: dict[str, object] | None = None
    ) -> None:
        from puppetphone.games import load_game, make_app

        if device not in DEVICES or controller not in CONTROLLERS:
            raise ValueError(f"device must be one of {DEVICES} and controller one of {CONTROLLERS}")
        self.device = device
        # A game drawing ``fps`` frames a second handles the mouse's queued events once a frame.
        self.burst, self._frame_steps = 1, max(1, int(round(60.0 / fps)))  # bursts start after the grab
        self._pending: list[pygame.event.Event] = []
        self._steps = 0
        self.source: PoseSource = _Phone() if device == "phone" else MouseSource()
        setup: dict[str, object] = {"scene": "empty", "puppets": 1}
        if character is not None:  # the player's puppet is a character (engine.character.setup value)
            setup["character"] = character
        self.app: App = make_app("sandbox", seed, InputHub([self.source]), setup)
        self.world = self.app.world
        self.puppet = next(e for e, _ in self.world.query(Brain))
        body = self.world.get(self.puppet, PuppetBody)
        body.tuning = replace(body.tuning, controller=controller)
        # Facing the way the cases lead: the time to 90 % is a speed step, not a turn on the spot.
        body.heading = float(np.arctan2(_WAY[0], _WAY[1]))
        self.world.get(self.puppet, Transform).rotation = quat.from_axis_angle([0.0, 1.0, 0.0], body.heading)
        self.camera = load_game("sandbox").camera()
        self.size = (1280, 720)
        self.sk = self.world.get(self.puppet, Puppet).skeleton
        self.feet = [self.sk.index(n) for n in ("l_foot", "r_foot")]
        self.time = 0.0
        self.clock = 0.0  # seconds since the drag began (the cases' time)
        self.offset = np.zeros(3)  # phone: its tracked position; the stick tip moves with it
        self.orientation = quat.identity()
        self.lift = 0.0  # phone height offset / mouse cursor rise in pixels (flicks)
        self.run = Run(self.world.dt, np.zeros((0, 2, 3)), np.zeros((0, 2, 3)), np.zeros((0, 3)), [], [])
        self._rows: list[tuple[F, F, F, str, Jumping]] = []
        self.airborne: list[float | None] = []  # per step: the airborne clip's time, while it plays

    # -- devices ------------------------------------------------------------------
    def _phone_sample(self, t: float, touch: bool | None = None, calibrate: bool = False) -> None:
        position = self.offset + np.array([0.0, self.lift, 0.0])
        self.source.push(
            PoseSample(
                time=t,
                source="phone",
                orientation=self.orientation,
                position=position,
                touch=touch,
                calibrate=calibrate,
            )
        )

    def _mouse_event(self, kind: int, t: float, **attrs: object) -> None:
        """Hand a mouse event to the source at its event time, or, drawing slowly (``burst`` steps
        a frame), queue it for the next frame, which handles the queue at once as the game does."""
        assert isinstance(self.source, MouseSource)
        if self.burst == 1:
            self.source.handle_event(pygame.event.Event(kind, attrs), self.camera, self.size, now=t)
        else:
            self._pending.append(pygame.event.Event(kind, attrs))

    def _advance(self) -> None:
        """One simulation step (after the frame's events, when a frame starts) and its record."""
        if self.burst > 1 and self._steps % self.burst == 0:
            for event in self._pending:
                assert isinstance(self.source, MouseSource)  # only the mouse queues events
                self.source.handle_event(event, self.camera, self.size, now=self.time)
            self._pending.clear()
        self._steps += 1
        self.app.step()
        self._record()

    def _pixel(self, point: F) -> tuple[float, float]:
        px = self.camera.project(np.asarray(point, dtype=np.float64)[None], *self.size)[0]
        return float(px[0]), float(px[1] - self.lift)

    def step(self, hand: Callable[[float], tuple[F, float]] | None = None) -> None:
        """One 60 Hz step; the device reports ``hand(t) -> (ground, lift)`` (the stick's wanted ground
        offset and the hand's lift, ``t`` s since the drag began) at its own rate, each reading where
        the hand is at its event time."""
        dt = self.world.dt
        n = int(round(RATE * dt))
        for k in range(1, n + 1) if hand is not None else ():
            assert hand is not None  # the loop runs only with a hand
            ground, self.lift = hand(self.clock + dt * k / n)
            t = self.time + dt * k / n
            if self.device == "phone":
                self.offset = self.offset0 + np.array([ground[0], 0.0, ground[1]])
                self._phone_sample(t)
            else:
                px = self._pixel(np.array([self.tip0[0] + ground[0], self.height, self.tip0[2] + ground[1]]))
                self._mouse_event(pygame.MOUSEMOTION, t, pos=px, rel=(0, 0), buttons=(1, 0, 0))
        self.time += dt
        self.clock += dt
        self._advance()

    def _record(self) -> None:
        wp = self.world.try_get(self.puppet, WorldPose)
        if wp is None:
            toes = heels = np.full((2, 3), np.nan)
        else:
            toes = np.array([wp.positions[j] + quat.rotate(wp.rotations[j], self.sk.tips[j]) for j in self.feet])
            heels = np.array([wp.positions[j] + quat.rotate(wp.rotations[j], HEEL_OFFSET) for j in self.feet])
        brain = self.world.get(self.puppet, Brain)
        pos = self.world.get(self.puppet, Transform).position.copy()
        player = self.world.get(self.puppet, LocomotionPlayer)
        self.airborne.append(player.override_time if player.override == "mid_jump" else None)
        self._rows.append((toes, heels, pos, brain.active, replace(self.world.get(self.puppet, Jumping))))

    def grab(self) -> None:
        """Settle, point at the puppet's hips and press (a phone calibrates first)."""
        anchor = self.world.get(self.puppet, Grabbable).anchor(self.world.get(self.puppet, Transform))
        self.anchor0, self.offset0 = anchor.copy(), np.zeros(3)
        dt = self.world.dt
        if self.device == "phone":
            for _ in range(10):
                self._phone_sample(self.time)
                self.time += dt
                self.app.step()
            self._phone_sample(self.time, calibrate=True)
            self.time += dt
            self.app.step()
            d = anchor - np.asarray(self.world.resource(StickConfig).virtual_pivot, dtype=np.float64)
            self.orientation = quat.between(np.array([0.0, 0.0, 1.0]), d / np.linalg.norm(d))
            self._phone_sample(self.time, touch=True)
        else:
            px = self._pixel(anchor)
            self._mouse_event(pygame.MOUSEMOTION, self.time, pos=px, rel=(0, 0), buttons=(0, 0, 0))
            self.time += dt
            self.app.step()
            self._mouse_event(pygame.MOUSEBUTTONDOWN, self.time, pos=px, button=1)
        self.time += dt
        self.app.step()
        stick = next(s for _, s in self.world.query(Stick))
        if stick.grabbed != self.puppet:
            raise RuntimeError(f"the {self.device} did not grab the puppet")
        self.height, self.tip0 = float(stick.tip[1]), stick.tip.copy()
        for _ in range(15):
            self.step(lambda t: (np.zeros(2), 0.0))
        self._rows.clear()
        self.airborne.clear()
        self.clock = 0.0
        self.burst = self._frame_steps

    def result(self) -> Run:
        """The steps recorded since the grab."""
        rows = self._rows
        return Run(
            self.world.dt,
            np.array([r[0] for r in rows]),
            np.array([r[1] for r in rows]),
            np.array([r[2] for r in rows]),
            [r[3] for r in rows],
            [r[4] for r in rows],
        )


def drive(
    case: Case,
    device: str = "phone",
    controller: str = "spring",
    settle: float = 1.0,
    character: dict[str, object] | None = None,
) -> Run:
    """Play ``case`` with ``device`` and the given locomotion ``controller``; keep ``settle`` s after it.
    ``character`` (an :mod:`engine.character.setup` value) plays it with that character as the puppet."""
    d = _Driver(device, controller, character=character)
    d.grab()
    for _ in range(int(round((case.moving + settle) / d.world.dt))):
        d.step(lambda t: (case.path(t), 0.0))
    return d.result()


@dataclass(frozen=True)
class MotionFigures:
    """One case's figures (see the module docstring)."""

    slide_mean: float
    slide_p95: float
    lowest_sole: float
    time_to_90: float | None
    time_to_rest: float | None
    fell: bool


def _planted_speeds(toes: F, dt: float, contact_height: float = 0.03) -> F:
    """Horizontal speeds of toes ``[T, 2, 3]`` over the steps both ends of which are planted."""
    low = np.nanmin(toes[..., 1], axis=0, keepdims=True)
    near = toes[..., 1] <= low + contact_height
    both = near[1:] & near[:-1]
    speed = np.linalg.norm(np.diff(toes[..., [0, 2]], axis=0), axis=-1) / dt
    return speed[both]


def motion_figures(case: Case, run: Run) -> MotionFigures:
    """Measure a driven case (see the module docstring)."""
    dt = run.dt
    a, b = (int(round(x / dt)) for x in case.measure)
    speeds = _planted_speeds(run.toes[a:b], dt)
    soles = np.concatenate([run.toes[..., 1], run.heels[..., 1]], axis=-1)
    ground = np.linalg.norm(np.diff(run.position[:, [0, 2]], axis=0), axis=-1) / dt
    smooth = np.convolve(ground, np.ones(3) / 3, mode="same")
    t90 = rest = None
    if case.speed is not None:
        reached = np.flatnonzero(smooth >= 0.9 * case.speed)
        t90 = float((reached[0] + 1) * dt) if len(reached) else None
        end = int(round(case.moving / dt))
        still = np.flatnonzero(smooth[end:] < 0.1)
        rest = float(still[0] * dt) if len(still) else None
    return MotionFigures(
        slide_mean=float(speeds.mean()) if len(speeds) else 0.0,
        slide_p95=float(np.percentile(speeds, 95)) if len(speeds) else 0.0,
        lowest_sole=float(np.nanmin(soles)),
        time_to_90=t90,
        time_to_rest=rest,
        fell=PuppetState.RAGDOLL in run.states,
    )


def blend_alone_slide(speed: float, seconds: float = 3.0) -> tuple[float, float]:
    """The baseline: the puppet's blend for ``speed`` m/s played alone, measured the same way (mean, p95)."""
    from engine.blend.measure import play
    from engine.blend.puppet import puppet_locomotion
    from engine.fk import forward_kinematics, world_points

    loco = puppet_locomotion()
    height = float(loco.standing_heights(np.array([speed]))[0])
    res = loco.table.resolve_many(np.array([[speed, height]]))
    weights = loco.space.weights(res[0])
    dt = 1.0 / 60.0
    pb = play(loco.space, weights, int(round(seconds / dt)), dt, rate=res[3])
    sk = loco.space.clips[0].skeleton
    wpos, wrot = forward_kinematics(sk, pb.root, pb.rotations)
    feet = [sk.index(n) for n in ("l_foot", "r_foot")]
    toes = world_points(sk, wpos, wrot)[:, 0, feet]
    speeds = _planted_speeds(toes, dt)
    return float(speeds.mean()), float(np.percentile(speeds, 95))


@dataclass(frozen=True)
class JumpResult:
    """How one flick went: ``landed`` (Jump then Land, no fall), the reason of a fall, the apex
    height error against the arc predicted at take-off (m), the flick-to-take-off time (s),
    the puppet's ground speed through the landing crouch (m/s) and each step's ``poses``:
    the airborne clip's time (s) while one plays, else ``None``."""

    landed: bool
    reason: str | None
    apex_error: float | None
    takeoff_delay: float | None
    states: list[str]
    landing_speed: float | None = None
    heights: list[float] | None = None
    poses: list[float | None] | None = None


def _phone_flick(t: float) -> float:
    """An up-and-down flick of the phone: 0.3 m up in 0.1 s, back in 0.12 s."""
    return 0.3 * min(t / 0.1, 1.0) - 0.3 * min(max(t - 0.1, 0.0) / 0.12, 1.0)


def _mouse_flick(t: float) -> float:
    """An ordinary hand's mouse flick, in pixels of cursor rise: 140 px up in 0.06 s, back in 0.08 s."""
    return 140.0 * min(t / 0.06, 1.0) - 140.0 * min(max(t - 0.06, 0.0) / 0.08, 1.0)


Gesture = Callable[[float, F], tuple[F, float]]


def jump(
    speed: float,
    device: str = "phone",
    controller: str = "spring",
    gesture: Gesture | None = None,
    run_up: float = 1.5,
    after: float = 1.6,
    fps: float = 60.0,
) -> JumpResult:
    """Walk or run at ``speed`` m/s for ``run_up`` s, flick, and keep going for ``after`` s.

    ``gesture(t, ground) -> (ground, lift)`` changes the stick from the flick on (``t`` s
    since the flick; ``ground`` where the walk would be): the valid flick by default,
    an invalid gesture for the invalid sweep. ``fps`` below 60 plays a machine that draws
    that slowly: the mouse's events arrive in bursts, handled together once a frame."""
    d = _Driver(device, controller, fps=fps)
    d.grab()
    flick = _phone_flick if device == "phone" else _mouse_flick
    default: Gesture = lambda t, g: (g, flick(t))  # noqa: E731
    gesture = gesture or default
    dt = d.world.dt
    start = int(round(run_up / dt))

    def hand(t: float) -> tuple[F, float]:
        ground = _WAY * speed * t
        return gesture(t - run_up, ground) if t > run_up else (ground, 0.0)

    for _ in range(start + int(round(after / dt))):
        d.step(hand)
    run = d.result()
    states = run.states
    fell = PuppetState.RAGDOLL in states
    reason = next((j.invalid.value for j in run.jumps if j.invalid is not None), None)
    jumped = [i for i, s in enumerate(states) if s == PuppetState.JUMP]
    landed = bool(jumped) and PuppetState.LAND in states[jumped[0] :] and not fell
    apex_error = delay = None
    if jumped:
        air = [i for i in jumped if run.jumps[i].progress is not None]
        if air:
            predicted = run.jumps[air[0]].apex_height
            top = max(float(run.position[i][1]) for i in air) + d.world.get(d.puppet, PuppetBody).tuning.stand_height
            apex_error = None if predicted is None else abs(top - predicted)
            delay = (air[0] - start) * dt
    land = [i for i, s in enumerate(states) if s == PuppetState.LAND]
    landing_speed = None
    if len(land) > 1:
        span = run.position[land[-1]] - run.position[land[0]]
        landing_speed = float(np.hypot(span[0], span[2]) / ((land[-1] - land[0]) * dt))
    return JumpResult(
        landed,
        reason if fell else None,
        apex_error,
        delay,
        states,
        landing_speed,
        [float(p[1]) for p in run.position],
        d.airborne,
    )
