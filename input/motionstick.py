"""The MotionStick system (thesis §6.2.1): controller poses in, a ``Stick`` out.

The puppet hangs at the end of an invisible stick fixed to the controller. Each
step, for every controller entity (``Stick`` + :class:`StickState`):

1. take *every* sample of the source it is bound to this step (the first source
   that speaks, unless bound to one by name), in arrival order: the newest sets the
   pose, wheel notches (``depth_delta``) are summed, a flick in any sample counts, and
   each sample's tip feeds the velocity filter at its own timestamp (event time, not
   the step's), so a 125 Hz mouse or a 100 Hz phone loses nothing at 60 steps a
   second; a disconnect releases the puppet;
2. build the stick: ``"world"`` samples give pivot and orientation directly (the
   mouse: a stick held at the camera); ``"device"`` samples are turned by the
   calibration heading and pivot at a virtual phone position (moved by the tracked
   position for 6-DoF phones). "Point at the screen and tap" calibrates: the first
   tap of an uncalibrated device, or a sample with ``calibrate``, makes the current
   pointing direction the scene's forward;
3. ray-pick the grabbable the stick points at (``focus``: the renderer outlines it): its
   grab sphere or, for a posed puppet, any bone it is drawn with (:mod:`input.stick_pick`);
4. touch down grabs the focus, keeping the stick's length and the grabbed thing's
   rotation relative to the tip; touch up releases;
5. shorten the stick where the tip would go below the ground or into an
   :class:`~engine.components.Obstacle`;
6. filter the tip velocity (One Euro, stepped per sample by the time between samples;
   a step without samples steps it by ``dt`` at rest) and detect an upward flick; a
   filter state that is not finite starts again at rest.

Everything here runs on the fixed ``dt`` with state in components, so a replay
reproduces it bit for bit.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from engine import quat
from engine.components import Grabbable, Obstacle, Stick, Transform
from engine.ecs import Entity, World
from input.filters import OneEuro
from input.sample import DISCONNECT, TOUCH_DOWN, TOUCH_UP, InputFrame, PoseSample
from input.stick_geometry import shorten
from input.stick_pick import stick_target

__all__ = ["StickState", "StickConfig", "motionstick_system", "spawn_stick"]

from engine.arrays import F64 as F

_Z = np.array([0.0, 0.0, 1.0])


@dataclass
class StickConfig:
    """Scene-level stick settings (a resource; hashed because it shapes the simulation)."""

    virtual_pivot: F = field(default_factory=lambda: np.array([0.0, 1.4, -3.0]))
    forward: F = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    ground_y: float = 0.0
    idle_length: float = 3.0
    min_depth: float = 0.3
    max_pick: float = 50.0
    flick_speed: float = 2.5
    filter: OneEuro = field(default_factory=OneEuro)

    SIM_STATE = True


@dataclass
class StickState:
    """Per-controller state behind a ``Stick``: binding, calibration, grab depth, filter."""

    binding: str = "*"
    source: str = ""
    yaw: F = field(default_factory=quat.identity)
    origin: F = field(default_factory=lambda: np.zeros(3))
    calibrated: bool = False
    held_length: float = 0.0
    depth: float = 0.0
    plane_normal: F | None = None
    filt_x: F | None = None
    raw_x: F = field(default_factory=lambda: np.zeros(3))
    filt_dx: F = field(default_factory=lambda: np.zeros(3))
    flick_armed: bool = True
    world_mode: bool = False
    last_time: float | None = None


def spawn_stick(world: World, binding: str = "*") -> Entity:
    """A controller entity driven by ``binding`` (a source id, or ``"*"`` for the first that speaks)."""
    return world.spawn(Stick(source=binding), StickState(binding=binding))


def _heading_yaw(direction: F, forward: F) -> F:
    """Rotation about +Y taking ``direction``'s heading to ``forward``'s."""
    a = np.arctan2(direction[0], direction[2])
    b = np.arctan2(forward[0], forward[2])
    if np.hypot(direction[0], direction[2]) < 1e-6:
        return quat.identity()
    return quat.from_axis_angle([0.0, 1.0, 0.0], b - a)


def _apply_sample(st: StickState, stick: Stick, s: PoseSample, cfg: StickConfig) -> None:
    st.world_mode = s.mode == "world"
    if s.mode == "world":
        stick.orientation = s.orientation.copy()
        if s.position is not None:
            stick.pivot = s.position.copy()
    else:
        if s.calibrate:
            _calibrate(st, s, cfg)
        stick.orientation = quat.normalize(quat.mul(st.yaw, s.orientation))
        offset = np.zeros(3) if s.position is None else quat.rotate(st.yaw, s.position - st.origin)
        stick.pivot = cfg.virtual_pivot + offset
    stick.direction = quat.rotate(stick.orientation, _Z)
    if s.plane_normal is not None:
        st.plane_normal = s.plane_normal.copy()


def _calibrate(st: StickState, s: PoseSample, cfg: StickConfig) -> None:
    st.yaw = _heading_yaw(quat.rotate(s.orientation, _Z), cfg.forward)
    st.origin = np.zeros(3) if s.position is None else s.position.copy()
    st.calibrated = True


def _grab(world: World, st: StickState, stick: Stick, target: Entity) -> None:
    tr = world.try_get(target, Transform)
    gr = world.try_get(target, Grabbable)
    if tr is None:
        return
    anchor = tr.position if gr is None else gr.anchor(tr)
    rel = anchor - stick.pivot
    st.held_length = float(np.linalg.norm(rel))
    st.depth = float(rel @ st.plane_normal) if st.plane_normal is not None else st.held_length
    # A held plane (the mouse): the tip is where the ray meets the anchor's plane, as in every later step
    # (:func:`_length`), so the grab offset lies in that plane. Measured along the ray instead, a press above
    # the anchor (a snowman's middle ball over its hips) held it lower than it stood: it crouched at once.
    tip = stick.pivot + stick.direction * _length(st, stick, 0.0, StickConfig(), None, holding=True)
    inv = quat.conjugate(stick.orientation)
    stick.grab_offset = quat.rotate(inv, anchor - tip)
    stick.grab_rotation = quat.normalize(quat.mul(inv, tr.rotation))
    stick.grabbed, stick.just_grabbed = target, True
    st.filt_x = None  # the tip jumps to the held length: a grab is not a velocity


def _release(stick: Stick) -> None:
    if stick.grabbed is not None:
        stick.grabbed, stick.released = None, stick.grabbed


def _length(
    st: StickState, stick: Stick, depth_delta: float, cfg: StickConfig, focus_t: float | None, holding: bool = False
) -> float:
    if stick.grabbed is None and not holding:
        return focus_t if focus_t is not None else cfg.idle_length
    if depth_delta:
        st.depth = max(cfg.min_depth, st.depth + depth_delta)
        if st.plane_normal is None:
            st.held_length = st.depth
    if st.plane_normal is not None:
        cos = float(stick.direction @ st.plane_normal)
        return st.depth / max(cos, 0.05)
    return st.held_length


def _obstacles(world: World, skip: Entity | None) -> tuple[F, F, F]:
    rows = [(tr.position, ob.radius, ob.height) for e, ob, tr in world.query(Obstacle, Transform) if e != skip]
    if not rows:
        return np.zeros((0, 3)), np.zeros(0), np.zeros(0)
    return np.array([r[0] for r in rows]), np.array([r[1] for r in rows]), np.array([r[2] for r in rows])


def motionstick_system(world: World) -> None:
    """The ``stick`` stage: update every controller's ``Stick`` from this step's ``InputFrame``."""
    frame = world.try_resource(InputFrame) or InputFrame(frame=world.frame)
    cfg = world.try_resource(StickConfig) or StickConfig()
    grabbables = world.query(Grabbable, Transform)
    for e, stick, st in world.query(Stick, StickState):
        stick.just_grabbed = stick.flick = False
        stick.released = None
        if st.source and frame.has_event(DISCONNECT, st.source):
            _release(stick)
            stick.touching, stick.connected = False, False
            if st.binding == "*":
                st.source = ""
        if not st.source:
            first = frame.samples[0].source if frame.samples else None
            if st.binding != "*":
                first = st.binding if frame.latest(st.binding) is not None else None
            if first is None:
                continue
            st.source, stick.source, stick.connected = first, first, True
        samples = frame.samples_of(st.source)
        s = samples[-1] if samples else None
        poses: list[tuple[F, F, float]] = []  # each sample's pivot, direction and time (for the velocity)
        for sample in samples:
            stick.connected = True
            _apply_sample(st, stick, sample, cfg)
            poses.append((stick.pivot.copy(), stick.direction.copy(), sample.time))
        if stick.grabbed is not None and not world.alive(stick.grabbed):
            _release(stick)
        # Ray pick: what would be grabbed now (the renderer outlines it).
        hit = stick_target(world, grabbables, stick.pivot, stick.direction, cfg.max_pick, skip=stick.grabbed)
        stick.focus = hit[0] if hit is not None else None
        for kind, src in frame.events:
            if src != st.source:
                continue
            if kind == TOUCH_DOWN:
                stick.touching = True
                if s is not None and s.mode == "device" and not st.calibrated:
                    _calibrate(st, s, cfg)  # "point at the screen and tap"
                    _apply_sample(st, stick, s, cfg)
                elif stick.focus is not None and stick.grabbed is None:
                    _grab(world, st, stick, stick.focus)
            elif kind == TOUCH_UP:
                stick.touching = False
                _release(stick)
        focus_t = None if hit is None else hit[1]
        notches = sum(x.depth_delta for x in samples)
        before = _length(st, stick, 0.0, cfg, focus_t)
        wanted = _length(st, stick, notches, cfg, focus_t)
        if notches and st.filt_x is not None:
            # A wheel notch lowers or lifts what is held (crouch, lift): the tip's jump along the
            # stick is not the hand moving, so the velocity filter moves with it.
            shift = stick.direction * (wanted - before)
            st.filt_x, st.raw_x = st.filt_x + shift, st.raw_x + shift
        bases, radii_o, heights = _obstacles(world, stick.grabbed)
        tips = [
            (pivot + d * shorten(pivot, d, wanted, cfg.ground_y, bases, radii_o, heights), t) for pivot, d, t in poses
        ]
        stick.length = shorten(stick.pivot, stick.direction, wanted, cfg.ground_y, bases, radii_o, heights)
        stick.tip = stick.pivot + stick.direction * stick.length
        stick.tip_rotation = stick.orientation.copy()
        if tips:
            tips[-1] = (stick.tip.copy(), tips[-1][1])
        _filter_velocity(st, stick, tips, any(x.flick for x in samples), cfg, world.dt)
        # Samples are range-checked where they enter (input.sample.LIMITS), so this never fires;
        # if it does, a NaN was about to enter the world: stop here, not in a later stage.
        assert np.isfinite(stick.tip).all() and np.isfinite(stick.velocity).all(), f"stick {e} is not finite"


def _filter_velocity(
    st: StickState, stick: Stick, tips: list[tuple[F, float]], flicked: bool, cfg: StickConfig, dt: float
) -> None:
    """Feed each sample's tip to the One Euro filter at its own time; detect a flick.

    The time between samples comes from their timestamps, at most 0.1 s (a long silence
    must not make the rate vanish); a source whose stamps do not advance (equal or
    backwards) gets the step shared evenly between its samples, so a burst never blows the
    rate up. A step without samples holds the tip still for ``dt``: a mouse that stops
    sends nothing."""
    steps: list[tuple[F, float | None]] = list(tips) or [(stick.tip.copy(), None)]
    share = dt / len(steps)
    for tip, stamp in steps:
        if st.filt_x is None:
            st.filt_x, st.filt_dx = tip.copy(), np.zeros(3)
        else:
            gap = share if stamp is None or st.last_time is None else float(stamp - st.last_time)
            gap = min(gap, 0.1) if gap > 1e-4 else share
            st.filt_x, st.filt_dx = cfg.filter.step(tip, st.raw_x, st.filt_x, st.filt_dx, gap)
            if not (np.all(np.isfinite(st.filt_x)) and np.all(np.isfinite(st.filt_dx))):
                # A filter keeps what it is fed for good: start again at rest rather than carry NaN
                # into every later step (and into the puppet's locomotion request).
                st.filt_x, st.filt_dx = tip.copy(), np.zeros(3)
        st.raw_x = tip.copy()
        st.last_time = (st.last_time + dt if st.last_time is not None else None) if stamp is None else float(stamp)
    stick.velocity = st.filt_dx.copy()
    up = float(stick.velocity[1])
    # A "world" source (the mouse) says itself when it flicks: its tip jumps with wheel
    # notches and cursor warps, so its velocity is not a gesture. Devices flick by velocity.
    by_velocity = not st.world_mode and st.flick_armed and stick.grabbed is not None and up > cfg.flick_speed
    if flicked or by_velocity:
        stick.flick, st.flick_armed = True, False
    elif up < 0.5 * cfg.flick_speed:
        st.flick_armed = True
