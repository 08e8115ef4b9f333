"""What a puppet's brain keeps between steps, and the tuning it reads.

:class:`PuppetBody` is what every state reads: the stick as the puppet senses it and
the locomotion control (hashed: it is simulation state). What only some states use
lives in a small component of its own, present on every puppet and reset by the
state that owns it: :class:`Jumping` (Jump), :class:`Landing` (Land),
:class:`GettingUp` (GetUp) and :class:`Handling` (PickUp, Carry, PutDown,
RollSnowball) — so a game rule reads or steers a puppet through typed fields, never
through string keys. :class:`PuppetTuning` holds the thresholds of the behaviour —
immutable data a game may replace (a snowman jumps lower, its crouch is shallower).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum

import numpy as np

from engine.ecs import Entity
from engine.pose import Pose
from engine.ragdoll.getup import GetUpBlend, LyingOrientation
from engine.rows import keep_in_rows
from engine.statemachine.jump_arc import JumpStatus, JumpTracker

__all__ = [
    "PuppetBody",
    "PuppetTuning",
    "PoseOverride",
    "Jumping",
    "JumpPhase",
    "Landing",
    "GettingUp",
    "Handling",
    "PUPPET_COMPONENTS",
]

from engine.arrays import F64 as F


@dataclass(frozen=True)
class PuppetTuning:
    """Thresholds and rates of the puppet behaviour (thesis §6.2.2, §6.3).

    Heights are hips heights in metres; speeds in m/s. ``front`` is how far the body
    reaches in front of its root: balls are carried, rolled and put down beyond it, so
    a bulky puppet (a snowman's bottom ball) never holds a ball inside itself.

    ``controller`` picks the locomotion control: ``"spring"`` (a critically damped spring
    on the requested velocity, :mod:`~engine.statemachine.puppet.follow`) or ``"legacy"``
    (the hard-switched follower of earlier rounds, kept so ``bench motion`` compares them).
    ``max_speed`` caps the legacy request and sets what counts as running; the spring
    controller asks up to ``top_speed`` and lets the lookup table speed the clips up.
    """

    controller: str = "spring"
    stand_height: float = 0.95
    crouch_height: float = 0.55
    crouch_enter: float = 0.80
    crouch_exit: float = 0.86
    lift_limit: float = 0.25
    max_speed: float = 3.4
    catch_up_gain: float = 2.5
    follow_deadband: float = 0.06
    turn_rate: float = 5.0
    drag_limit: float = 1.6
    drag_lead_time: float = 0.5
    top_speed: float = 6.0
    follow_omega: float = 40.0
    anticipation: float = 0.16
    landing: float = 0.22
    flick_launch_speed: float = 3.4
    flick_grace: float = 0.1
    jump_ragdoll_fall: float = 0.0
    reach: float = 0.55
    front: float = 0.22
    carry_max_radius: float = 0.26
    pickup_time: float = 0.35
    still_speed: float = 0.2
    still_time: float = 0.3
    gravity: float = 9.81


@dataclass
class PoseOverride:
    """A pose that replaces the animated one after the animation stage (get-up), with a weight."""

    pose: Pose | None = field(default=None, metadata={"hash": False})
    weight: float = 0.0
    SIM_STATE = True


@dataclass
class PuppetBody:
    """What every state of a puppet reads: the stick as sensed, the facing and the locomotion control.

    Attributes:
        tuning: behaviour thresholds (an asset).
        held_by: the controller entity whose stick holds this puppet, if any.
        target: where the stick wants the puppet's ground position.
        target_height: hips height the stick asks for (its tip's height).
        heading: facing angle about +Y (0 = +Z).
        speed: smoothed stick ground speed.
        lead: the stick's ground velocity (the feed-forward of the locomotion control).
        walk_velocity: the requested ground velocity, smoothed by the control's spring.
        walk_rate: the spring's rate of change of ``walk_velocity``.
        recent: ``[12, 3]`` the ground velocities asked of the puppet over the last 0.2 s (the
            spring's ``walk_velocity``), oldest first: a jump goes where the hand was leading
            just before the flick (a puppet still turning round after a reversal jumps the way
            it is led), not where a stroke's burst of mouse events jerked the request.
        ground_velocity: the puppet's measured ground velocity over the last step (its momentum).
        last_position: where it stood a step ago (for ``ground_velocity``).
    """

    tuning: PuppetTuning = field(default_factory=PuppetTuning, metadata={"hash": False})
    held_by: int | None = None
    target: F = field(default_factory=lambda: np.zeros(3))
    target_height: float = 0.95
    heading: float = 0.0
    speed: float = 0.0
    lead: F = field(default_factory=lambda: np.zeros(3))
    walk_velocity: F = field(default_factory=lambda: np.zeros(3))
    walk_rate: F = field(default_factory=lambda: np.zeros(3))
    recent: F = field(default_factory=lambda: np.zeros((12, 3)))
    ground_velocity: F = field(default_factory=lambda: np.zeros(3))
    last_position: F | None = None


class JumpPhase(Enum):
    """The two parts of a jump: the squat before take-off, then the arc."""

    ANTICIPATION = "anticipation"
    AIR = "air"


@dataclass
class Jumping:
    """The Jump state's data (:mod:`~engine.statemachine.puppet.jump_state`).

    Attributes:
        phase: anticipation or airborne.
        timer: seconds in the current phase.
        air: height of the root above the ground (0 on the ground).
        air_velocity: the puppet's velocity while airborne (ballistic jumps).
        tracker: the arc tracker of the current jump (``None`` before take-off).
        from_stick: whether the stick's own path drives the arc (phones) or a flick launched it (mouse).
        apex_height: the predicted apex height of the last jump (0 until it is known; ``None`` before any jump).
        progress: where the last jump is on its arc (0 take-off, 0.5 apex, 1 down; ``None`` before any).
        invalid: why the last jump was invalid, if it was (cleared when the next one starts).
    """

    phase: JumpPhase = JumpPhase.ANTICIPATION
    timer: float = 0.0
    air: float = 0.0
    air_velocity: F = field(default_factory=lambda: np.zeros(3))
    tracker: JumpTracker | None = None
    from_stick: bool = False
    apex_height: float | None = None
    progress: float | None = None
    invalid: JumpStatus | None = None


@dataclass
class Landing:
    """The Land state's data: seconds into the absorbing crouch and how deep it goes (0..1 of a full crouch)."""

    timer: float = 0.0
    depth: float = 0.7


@dataclass
class GettingUp:
    """The GetUp state's data: the blend in progress (its frame is hashed as ``frame``) and how the body lay."""

    blend: GetUpBlend | None = field(default=None, metadata={"hash": False})
    frame: float = 0.0
    lying: LyingOrientation | None = None


@dataclass
class Handling:
    """The data of the states that handle a ball: PickUp, Carry, PutDown and RollSnowball.

    Attributes:
        object: the prop being picked up, carried, put down or rolled.
        timer: seconds into reaching (PickUp) or lowering (PutDown).
        raised: the stick was raised while carrying (only a lowering after that puts the ball down).
        spot: where a put-down ball goes on the ground.
        onto: the bigger ball a put-down ball goes on top of (a game may re-aim it to a stack's top).
        left: the ball just put down, left alone until the puppet stands up again.
    """

    object: Entity | None = None
    timer: float = 0.0
    raised: bool = False
    spot: F | None = None
    onto: Entity | None = None
    left: Entity | None = None


keep_in_rows(
    PuppetBody,
    tuning=("object", (), False),
    held_by=("int", (), True),
    heading=("float", (), False),
    speed=("float", (), False),
    lead=("vector", (3,), False),
    walk_velocity=("vector", (3,), False),
    walk_rate=("vector", (3,), False),
    recent=("vector", (12, 3), False),
    ground_velocity=("vector", (3,), False),
    last_position=("vector", (3,), True),
)
"""A crowd's bodies keep what the brain stage updates every step in arrays (:mod:`engine.rows`): the stage
reads and writes them whole, and a reader of one puppet sees the same values as plain fields."""

keep_in_rows(Handling, left=("int", (), True))
"""Locomotion lets go of the ball a puppet left (``left = None``) for the whole crowd at once."""

keep_in_rows(Jumping, air=("float", (), False))
"""Who is on the ground is one array comparison for a crowd (a wandering crowd steers only those)."""

PUPPET_COMPONENTS = (Jumping, Landing, GettingUp, Handling)
"""The per-state components every puppet carries (a spawned puppet gets one fresh instance of each)."""
