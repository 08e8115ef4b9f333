"""What a puppet's brain keeps between steps, and the tuning it reads.

:class:`PuppetBody` is the per-puppet component (hashed: it is simulation state);
:class:`PuppetTuning` holds the thresholds of the behaviour — immutable data a game
may replace (a snowman jumps lower, its crouch is shallower).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from engine.pose import Pose
from engine.statemachine.jump_arc import JumpTracker

__all__ = ["PuppetBody", "PuppetTuning", "PoseOverride"]

F = NDArray[np.float64]


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
    """Per-puppet brain state.

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
        air: height of the root above the ground during a jump.
        air_velocity: the puppet's velocity while airborne (ballistic jumps).
        ground_velocity: the puppet's measured ground velocity over the last step (its momentum).
        last_position: where it stood a step ago (for ``ground_velocity``).
        jump: the arc tracker of the current jump.
        land_depth: how deep the landing crouch goes (0..1 of a full crouch), from the landing speed.
        jump_from_stick: whether the stick's own path drives the arc (phones) or a flick launched it (mouse).
        object: the prop carried or rolled.
        timer: seconds in the current phase of a multi-phase state.
        phase: the phase name within a state (``"anticipation"``, ``"air"``…).
        getup: the get-up blend in progress (an object; its frame is hashed through ``timer``).
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
    air: float = 0.0
    air_velocity: F = field(default_factory=lambda: np.zeros(3))
    ground_velocity: F = field(default_factory=lambda: np.zeros(3))
    last_position: F | None = None
    jump: JumpTracker | None = None
    land_depth: float = 0.7
    jump_from_stick: bool = False
    object: int | None = None
    timer: float = 0.0
    phase: str = ""
    getup: Any = field(default=None, metadata={"hash": False})
