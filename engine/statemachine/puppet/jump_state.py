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

Either way the apex drives the pose (tuck on the way up, open toward landing), and
the jump is *invalid* if it rises again after starting to fall, turns in the air or
stops in the air: the brain raises ``jump_invalid`` and the ragdoll takes over.
Otherwise the puppet lands, absorbs the shock with a short crouch (Land), and then
rejoins the stick, which has meanwhile moved along the jump path.
"""

from __future__ import annotations

import numpy as np

from engine.blend.locomotion import LocomotionPlayer
from engine.components import Stick, Transform
from engine.ecs import Entity, World
from engine.ik.system import IKRequest
from engine.statemachine.jump_arc import JumpStatus, JumpTracker
from engine.statemachine.machine import Brain
from engine.statemachine.puppet.body import PuppetBody
from engine.statemachine.puppet.senses import holder, wanted_anchor

__all__ = ["enter_jump", "update_jump", "exit_jump", "enter_land", "update_land", "landing_done", "jump_wanted"]


def jump_wanted(world: World, entity: Entity, brain: Brain) -> bool:
    """A flick of the stick holding this puppet."""
    held = holder(world, entity)
    return held is not None and held[1].flick


def enter_jump(world: World, entity: Entity, brain: Brain) -> None:
    """Start the anticipation squat."""
    body = world.get(entity, PuppetBody)
    player = world.get(entity, LocomotionPlayer)
    body.phase, body.timer, body.air = "anticipation", 0.0, 0.0
    body.jump = None
    # The puppet's own momentum, taken before the squat slows it: a mouse flick's
    # stroke says "jump", never where to — the stick's velocity during it is a gesture.
    body.air_velocity = body.ground_velocity.copy()
    player.height = body.tuning.crouch_height + 0.12
    player.speed *= 0.5
    brain.memory["jump_apex_height"] = 0.0
    brain.memory.pop("jump_invalid", None)


def _take_off(world: World, entity: Entity, body: PuppetBody, stick: Stick | None) -> None:
    tr = world.get(entity, Transform)
    t = body.tuning
    start = tr.position + np.array([0.0, t.stand_height, 0.0])
    rising = stick is not None and float(wanted_anchor(stick)[1]) > t.stand_height + 0.1 and stick.velocity[1] > 0.5
    body.jump_from_stick = bool(rising)
    if rising:
        velocity = stick.velocity.copy()
    else:
        horizontal = np.array([body.air_velocity[0], 0.0, body.air_velocity[2]])
        n = float(np.linalg.norm(horizontal))
        if n > t.max_speed:
            horizontal *= t.max_speed / n
        velocity = horizontal + np.array([0.0, t.flick_launch_speed, 0.0])
    body.air_velocity = velocity
    body.jump = JumpTracker.start_at(start, velocity)
    body.phase, body.timer = "air", 0.0
    world.get(entity, LocomotionPlayer).play("mid_jump", fade=0.1)


def update_jump(world: World, entity: Entity, brain: Brain) -> None:
    """Advance the jump: anticipation, then the arc; raise ``landed`` or ``jump_invalid``."""
    body = world.get(entity, PuppetBody)
    player = world.get(entity, LocomotionPlayer)
    tr = world.get(entity, Transform)
    ik = world.try_get(entity, IKRequest)
    held = holder(world, entity)
    stick = None if held is None else held[1]
    t = body.tuning
    body.timer += world.dt
    if body.phase == "anticipation":
        if ik is not None:
            ik.grounding = True
        if body.timer >= t.anticipation:
            _take_off(world, entity, body, stick)
        return
    if ik is not None:
        ik.grounding = False
    player.speed, player.height = 0.0, None
    assert body.jump is not None
    if body.jump_from_stick and stick is not None:
        anchor = wanted_anchor(stick)
        velocity = stick.velocity.copy()
        tr.position = np.array([anchor[0], max(anchor[1] - t.stand_height, 0.0), anchor[2]])
        point = anchor
    else:
        body.air_velocity = body.air_velocity - np.array([0.0, t.gravity * world.dt, 0.0])
        tr.position = tr.position + body.air_velocity * world.dt
        velocity = body.air_velocity
        point = tr.position + np.array([0.0, t.stand_height, 0.0])
        lead = None if stick is None else np.array([stick.velocity[0], 0.0, stick.velocity[2]])
        if lead is not None and body.timer >= t.flick_grace and float(np.linalg.norm(lead)) <= t.max_speed:
            # The mouse's stick stays in its plane: leading sideways turns the jump and
            # holding still stops it. Faster than any run is the flick stroke still
            # fading from the filtered velocity, not a lead: ignored.
            velocity = np.array([lead[0], body.air_velocity[1], lead[2]])
    body.air = float(tr.position[1])
    predicted = body.jump.apex.copy()
    status = body.jump.update(point, velocity, world.dt, body.air)
    if not body.jump_from_stick:
        # Ballistic: the apex is exact (the tracker's refit would mix the stick's lead in);
        # once past it, the last prediction stands.
        vy = float(body.air_velocity[1])
        if vy > 0.0:
            rise = vy / t.gravity
            along = float(body.jump.direction @ body.air_velocity[[0, 2]]) if np.any(body.jump.direction) else 0.0
            predicted = np.array([body.jump.side_view(point)[0] + along * rise, point[1] + 0.5 * vy * rise])
        body.jump.apex = predicted
    if np.isfinite(body.jump.apex).all():
        brain.memory["jump_apex_height"] = float(body.jump.apex[1])
    if status in (JumpStatus.ROSE_AGAIN, JumpStatus.TURNED, JumpStatus.STOPPED):
        brain.memory["jump_invalid"] = status.value
        brain.raise_event("jump_invalid")
    elif tr.position[1] <= 0.0 and (status is JumpStatus.LANDED or body.air_velocity[1] < 0 or body.jump.descending):
        tr.position = np.array([tr.position[0], 0.0, tr.position[2]])
        brain.raise_event("landed")


def exit_jump(world: World, entity: Entity, brain: Brain) -> None:
    """Leave the air: back on the ground plane, the override clip fading out."""
    body = world.get(entity, PuppetBody)
    tr = world.get(entity, Transform)
    world.get(entity, LocomotionPlayer).stop(0.15)
    if brain.memory.get("jump_invalid") is None:
        tr.position = np.array([tr.position[0], 0.0, tr.position[2]])
    body.air = 0.0
    body.jump = None


def enter_land(world: World, entity: Entity, brain: Brain) -> None:
    """Absorb the landing with a short crouch."""
    body = world.get(entity, PuppetBody)
    body.phase, body.timer = "land", 0.0


def update_land(world: World, entity: Entity, brain: Brain) -> None:
    """A quick dip of the hips and back up, then the puppet rejoins the stick."""
    body = world.get(entity, PuppetBody)
    player = world.get(entity, LocomotionPlayer)
    t = body.tuning
    body.timer += world.dt
    s = min(body.timer / t.landing, 1.0)
    dip = np.sin(np.pi * s)
    player.height = float(t.stand_height - dip * (t.stand_height - t.crouch_height) * 0.7)
    player.speed = 0.0
    ik = world.try_get(entity, IKRequest)
    if ik is not None:
        ik.grounding = True


def landing_done(world: World, entity: Entity, brain: Brain) -> bool:
    """The absorbing crouch is over."""
    body = world.get(entity, PuppetBody)
    return body.timer >= body.tuning.landing
