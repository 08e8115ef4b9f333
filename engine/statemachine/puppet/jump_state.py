"""Jump and Land (thesis §6.3): anticipation, a tracked arc, and an absorbing landing.

Lifting the stick fast enough (a *flick*) triggers the jump. The puppet first
squats for a short forced delay (the animation principle of anticipation), then
takes off. Two drivers of the arc exist:

- the stick's own path, when the controller really rises (a phone lifted up): the
  puppet rides the stick tip and the parabola of Eq. 6.3 is refitted every frame
  from the start point, the current point and the current slope
  (:class:`~engine.statemachine.jump_arc.JumpTracker`);
- a ballistic launch, when the flick came from a controller that stays in its
  plane (the mouse): the flick's speed launches the puppet, gravity brings it down.

Either way the arc drives the pose: the airborne clip is not played by the clock but
sampled by the puppet's place on its arc — from take-off to the apex it tucks, from the
apex to the ground it opens again — so a higher or longer jump looks higher or longer.
The jump is *invalid* if it rises again after starting to fall, turns in the air, stops
in the air or is pulled down hard (tolerances in :mod:`engine.statemachine.jump_arc`,
judged against the motion the jump already has): the brain raises ``jump_invalid`` and
the ragdoll takes over. Otherwise the puppet lands with a crouch as deep as the landing
was fast (Land) and keeps its horizontal speed: a running jump lands running, and the
puppet rejoins the stick, which has meanwhile moved along the jump path.
"""

from __future__ import annotations

import numpy as np

from engine.blend.locomotion import BlendLibrary, LocomotionPlayer
from engine.components import Stick, Transform
from engine.ecs import Entity, World
from engine.ik.system import IKRequest
from engine.statemachine.jump_arc import JumpStatus, JumpTracker
from engine.statemachine.machine import Brain
from engine.statemachine.puppet.body import Jumping, JumpPhase, Landing, PuppetBody
from engine.statemachine.puppet.ground_states import follow_stick
from engine.statemachine.puppet.names import PuppetEvent, PuppetState
from engine.statemachine.puppet.senses import holder, wanted_anchor
from engine.statemachine.puppet.spec import PuppetStateDef, PuppetTransition, StateSpec, held_rows

__all__ = [
    "enter_jump",
    "update_jump",
    "exit_jump",
    "enter_land",
    "update_land",
    "landing_done",
    "jump_wanted",
    "arc_progress",
    "SPEC",
]


def jump_wanted(world: World, entity: Entity, brain: Brain) -> bool:
    """A flick of the stick holding this puppet."""
    held = holder(world, entity)
    return held is not None and held[1].flick


def enter_jump(world: World, entity: Entity, brain: Brain) -> None:
    """Start the anticipation squat."""
    body = world.get(entity, PuppetBody)
    jump = world.get(entity, Jumping)
    player = world.get(entity, LocomotionPlayer)
    jump.phase, jump.timer, jump.air = JumpPhase.ANTICIPATION, 0.0, 0.0
    jump.tracker = None
    # The puppet's own momentum, taken before the squat slows it: a mouse flick's
    # stroke says "jump", never where to — the stick's velocity during it is a gesture.
    # The velocity it was asked for 0.2 s ago, before the stroke began: not the last step's
    # displacement, which sways with the gait (a run's hips swing side to side), nor the
    # request during the stroke, which a burst of mouse events can jerk aside.
    if body.tuning.controller == "legacy":
        jump.air_velocity = body.ground_velocity.copy()
    else:
        jump.air_velocity = body.recent[0].copy()
    player.height = body.tuning.crouch_height + 0.12
    player.speed *= 0.5
    jump.apex_height = 0.0
    jump.invalid = None


def _take_off(world: World, entity: Entity, body: PuppetBody, jump: Jumping, stick: Stick | None) -> None:
    tr = world.get(entity, Transform)
    t = body.tuning
    start = tr.position + np.array([0.0, t.stand_height, 0.0])
    rising = stick is not None and float(wanted_anchor(stick)[1]) > t.stand_height + 0.1 and stick.velocity[1] > 0.5
    jump.from_stick = bool(rising)
    if rising and stick is not None:
        velocity = stick.velocity.copy()
    else:
        horizontal = np.array([jump.air_velocity[0], 0.0, jump.air_velocity[2]])
        n = float(np.linalg.norm(horizontal))
        cap = t.max_speed if t.controller == "legacy" else t.top_speed
        if n > cap:
            horizontal *= cap / n
        velocity = horizontal + np.array([0.0, t.flick_launch_speed, 0.0])
    jump.air_velocity = velocity
    tracker = jump.tracker = JumpTracker.start_at(start, velocity)
    # A launched jump's line runs through where the stick is at take-off: what turns the jump
    # is the stick leaving that line, not a lag it already had (a puppet left behind by a
    # fast drag may still jump; the mouse's flick stroke does not move the stick).
    lead = start if stick is None else wanted_anchor(stick)
    tracker.lead_origin = np.array([lead[0], lead[2]], dtype=np.float64)
    jump.phase, jump.timer = JumpPhase.AIR, 0.0
    player = world.get(entity, LocomotionPlayer)
    player.play("mid_jump", fade=0.1)
    player.override_scrub = True


def arc_progress(tracker: JumpTracker, height: float) -> float:
    """Where a jump is on its arc, 0 at take-off, 0.5 at the apex, 1 back at take-off height.

    Read from the height against the predicted apex (the fitted parabola's), so it is the
    arc, not the clock, that poses the puppet."""
    y0, top = float(tracker.start[1]), float(tracker.apex[1]) if np.isfinite(tracker.apex).all() else np.nan
    if not np.isfinite(top) or top <= y0 + 1e-3:
        return 0.5 if tracker.descending else 0.0
    f = float(np.clip((height - y0) / (top - y0), 0.0, 1.0))
    return 1.0 - 0.5 * f if tracker.descending else 0.5 * f


def _pose_on_arc(world: World, player: LocomotionPlayer, progress: float) -> None:
    """The airborne clip at the arc's place: tucking up to the apex, opening after it."""
    clip = world.resource(BlendLibrary)[player.library_key].clips.get("mid_jump")
    if clip is not None and player.override == "mid_jump":
        player.override_time = clip.duration * (1.0 - abs(2.0 * progress - 1.0))


def update_jump(world: World, entity: Entity, brain: Brain) -> None:
    """Advance the jump: anticipation, then the arc; raise ``landed`` or ``jump_invalid``."""
    body = world.get(entity, PuppetBody)
    jump = world.get(entity, Jumping)
    player = world.get(entity, LocomotionPlayer)
    tr = world.get(entity, Transform)
    ik = world.try_get(entity, IKRequest)
    held = holder(world, entity)
    stick = None if held is None else held[1]
    t = body.tuning
    jump.timer += world.dt
    if jump.phase is JumpPhase.ANTICIPATION:
        if ik is not None:
            ik.grounding = True
        if jump.timer >= t.anticipation:
            _take_off(world, entity, body, jump, stick)
        return
    if ik is not None:
        ik.grounding = False
    player.speed, player.height = 0.0, None
    tracker = jump.tracker
    assert tracker is not None
    if jump.from_stick and stick is not None:
        anchor = wanted_anchor(stick)
        velocity = stick.velocity.copy()
        tr.position = np.array([anchor[0], max(anchor[1] - t.stand_height, 0.0), anchor[2]])
        point = anchor
        jump.air_velocity = velocity
    else:
        before = jump.air_velocity
        jump.air_velocity = before - np.array([0.0, t.gravity * world.dt, 0.0])
        tr.position = tr.position + 0.5 * (before + jump.air_velocity) * world.dt  # exact under gravity
        velocity = jump.air_velocity
        point = tr.position + np.array([0.0, t.stand_height, 0.0])
    jump.air = float(tr.position[1])
    status = tracker.update(point, velocity, world.dt, jump.air)
    if not jump.from_stick:
        # Launched: the apex is exact (ballistic); the stick only leads, and turns the jump
        # when it strays from the jump's line (the flick's own stroke comes back in time).
        vy = float(jump.air_velocity[1])
        if vy > 0.0:
            rise = vy / t.gravity
            along = float(tracker.direction @ jump.air_velocity[[0, 2]]) if np.any(tracker.direction) else 0.0
            tracker.apex = np.array([tracker.side_view(point)[0] + along * rise, point[1] + 0.5 * vy * rise])
        if stick is not None and status not in (JumpStatus.ROSE_AGAIN, JumpStatus.STOPPED):
            status = tracker.lead(wanted_anchor(stick), world.dt) or status
            if stick.flick and jump.timer >= t.flick_grace:
                status = JumpStatus.ROSE_AGAIN  # a second flick in mid-air: a hop off nothing
    if np.isfinite(tracker.apex).all():
        jump.apex_height = float(tracker.apex[1])
    progress = arc_progress(tracker, float(point[1]))
    jump.progress = progress
    _pose_on_arc(world, player, progress)
    if status in (JumpStatus.ROSE_AGAIN, JumpStatus.TURNED, JumpStatus.STOPPED, JumpStatus.PULLED_DOWN):
        jump.invalid = status
        brain.raise_event(PuppetEvent.JUMP_INVALID)
    elif tr.position[1] <= 0.0 and (status is JumpStatus.LANDED or jump.air_velocity[1] < 0 or tracker.descending):
        tr.position = np.array([tr.position[0], 0.0, tr.position[2]])
        brain.raise_event(PuppetEvent.LANDED)


def exit_jump(world: World, entity: Entity, brain: Brain) -> None:
    """Leave the air: back on the ground plane, the override clip fading out."""
    body = world.get(entity, PuppetBody)
    jump = world.get(entity, Jumping)
    tr = world.get(entity, Transform)
    player = world.get(entity, LocomotionPlayer)
    player.stop(0.15)
    player.override_scrub = False
    if jump.invalid is None:
        tr.position = np.array([tr.position[0], 0.0, tr.position[2]])
        # The jump's horizontal speed carries into the landing: a running jump lands running.
        body.walk_velocity = jump.air_velocity * np.array([1.0, 0.0, 1.0])
        body.walk_rate = np.zeros(3)
    jump.air = 0.0
    jump.tracker = None


def enter_land(world: World, entity: Entity, brain: Brain) -> None:
    """Absorb the landing with a short crouch."""
    land = world.get(entity, Landing)
    land.timer = 0.0
    # As deep as the landing was fast: a hop barely dips, a fall from high crouches low.
    land.depth = float(np.clip(-world.get(entity, Jumping).air_velocity[1] / 5.0, 0.25, 1.0))


def update_land(world: World, entity: Entity, brain: Brain) -> None:
    """A dip of the hips (scaled by the landing speed) and back up, still moving as the jump did."""
    body = world.get(entity, PuppetBody)
    land = world.get(entity, Landing)
    player = world.get(entity, LocomotionPlayer)
    t = body.tuning
    land.timer += world.dt
    s = min(land.timer / t.landing, 1.0)
    dip = np.sin(np.pi * s)
    player.height = float(t.stand_height - dip * (t.stand_height - t.crouch_height) * land.depth)
    if t.controller == "legacy":
        player.speed = 0.0
    else:
        follow_stick(world, entity, body, player)
    ik = world.try_get(entity, IKRequest)
    if ik is not None:
        ik.grounding = True


def landing_done(world: World, entity: Entity, brain: Brain) -> bool:
    """The absorbing crouch is over."""
    return world.get(entity, Landing).timer >= world.get(entity, PuppetBody).tuning.landing


_JUMP: PuppetStateDef = PuppetStateDef(
    PuppetState.JUMP,
    enter=enter_jump,
    update=update_jump,
    exit=exit_jump,
    description="anticipation squat, then the tracked arc (Eq. 6.3)",
)
_LAND: PuppetStateDef = PuppetStateDef(
    PuppetState.LAND, enter=enter_land, update=update_land, description="absorbing crouch"
)

SPEC = StateSpec(
    states=(_JUMP, _LAND),
    transitions=(
        # Jumps first: a flick wins over everything on the ground.
        PuppetTransition(
            PuppetState.LOCOMOTION,
            PuppetState.JUMP,
            guard=jump_wanted,
            batch_guard=held_rows,
            priority=20,
            crossfade=0.1,
            label="flick",
        ),
        PuppetTransition(
            PuppetState.CROUCH,
            PuppetState.JUMP,
            guard=jump_wanted,
            batch_guard=held_rows,
            priority=20,
            crossfade=0.1,
            label="flick",
        ),
        PuppetTransition(
            PuppetState.JUMP, PuppetState.RAGDOLL, event=PuppetEvent.JUMP_INVALID, priority=30, crossfade=0.1
        ),
        PuppetTransition(PuppetState.JUMP, PuppetState.LAND, event=PuppetEvent.LANDED, priority=25, crossfade=0.1),
        PuppetTransition(
            PuppetState.LAND, PuppetState.LOCOMOTION, guard=landing_done, crossfade=0.15, label="absorbed"
        ),
    ),
)
"""Jump and Land: the flick into the jump, the jump's end (landed or invalid) and the landing's."""
