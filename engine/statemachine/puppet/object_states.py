"""Pick up / carry / put down, and rolling a snowball (thesis §6.2.2, §6.3).

All of them are the crouch or walk animations adapted by IK: the hands are placed
on the object's surface (``IKRequest.sphere_centre``), independent of the clip.

- **PickUp**: crouched and still over a small ball, the hands reach it; after a
  moment the ball is lifted (the prop becomes ``carried``: physics follows it).
- **Carry**: walking with the ball held in front of the chest.
- **PutDown**: crouching while carrying sets the ball down in front — on top of a
  ball that is there, which is how snowmen are stacked.
- **RollSnowball**: crouch-walking into a ball pushes it along the ground in front
  of the puppet, rolling without slipping; the game decides how it grows.

Their data is the puppet's :class:`~engine.statemachine.puppet.body.Handling`
component (the ball, the timer, where a put-down ball goes): a game rule re-aims a
put-down by writing ``Handling.onto``.
"""

from __future__ import annotations

import numpy as np

from engine import quat
from engine.blend.locomotion import LocomotionPlayer
from engine.components import Transform
from engine.ecs import Entity, World
from engine.ik.system import IKRequest
from engine.ragdoll.components import Prop
from engine.statemachine.machine import Brain
from engine.statemachine.puppet.body import Handling, PuppetBody
from engine.statemachine.puppet.ground_states import follow_stick, locomotion_fits, wants_crouch
from engine.statemachine.puppet.names import PuppetState
from engine.statemachine.puppet.senses import heading_vector, prop_in_front, yaw_rotation
from engine.statemachine.puppet.spec import PuppetStateDef, PuppetTransition, StateSpec

_PICKUP_SPREAD = 0.35  # m to the side a small ball may be for a crouched puppet to turn and pick it up

__all__ = [
    "can_pick_up",
    "enter_pickup",
    "update_pickup",
    "pickup_done",
    "update_carry",
    "exit_carry",
    "enter_putdown",
    "update_putdown",
    "putdown_done",
    "exit_putdown",
    "putdown_spot",
    "can_roll",
    "enter_roll",
    "update_roll",
    "exit_roll",
    "stop_rolling",
    "carry_position",
    "wants_putdown",
    "SPEC",
]


def _hands(world: World, entity: Entity, centre: np.ndarray, radius: float) -> None:
    ik = world.try_get(entity, IKRequest)
    if ik is not None:
        ik.sphere_centre, ik.sphere_radius, ik.grounding = np.asarray(centre, dtype=np.float64), float(radius), True


def carry_position(world: World, entity: Entity, body: PuppetBody, radius: float) -> np.ndarray:
    """Where a carried ball sits: in front of the chest."""
    tr = world.get(entity, Transform)
    return (
        tr.position
        + np.array([0.0, body.tuning.stand_height + 0.1, 0.0])
        + heading_vector(body.heading) * (body.tuning.front + radius)
    )


def can_pick_up(world: World, entity: Entity, brain: Brain) -> bool:
    """Crouched, nearly still, a small free ball within reach in front -- not the one
    just put down, which stays put until the puppet has stood up again."""
    body = world.get(entity, PuppetBody)
    t = body.tuning
    if body.held_by is None or brain.time_in_state < t.still_time or body.speed > t.still_speed:
        return False
    ball = prop_in_front(world, entity, body, t.reach, t.carry_max_radius, spread=_PICKUP_SPREAD)
    return ball is not None and ball != world.get(entity, Handling).left


def enter_pickup(world: World, entity: Entity, brain: Brain) -> None:
    """Choose the ball and start reaching."""
    body = world.get(entity, PuppetBody)
    hand = world.get(entity, Handling)
    hand.object = prop_in_front(
        world, entity, body, body.tuning.reach, body.tuning.carry_max_radius, spread=_PICKUP_SPREAD
    )
    hand.raised, hand.timer = False, 0.0
    if hand.object is not None:  # a ball a little to the side: the puppet turns to it as it reaches
        d = world.get(hand.object, Transform).position - world.get(entity, Transform).position
        body.heading = float(np.arctan2(d[0], d[2]))
        world.get(entity, Transform).rotation = yaw_rotation(body.heading)


def update_pickup(world: World, entity: Entity, brain: Brain) -> None:
    """Hands to the ball; lift it once reached."""
    body = world.get(entity, PuppetBody)
    hand = world.get(entity, Handling)
    player = world.get(entity, LocomotionPlayer)
    player.speed, player.height = 0.0, body.tuning.crouch_height
    hand.timer += world.dt
    if hand.object is None or not world.alive(hand.object):
        return
    prop, ptr = world.get(hand.object, Prop), world.get(hand.object, Transform)
    if hand.timer >= body.tuning.pickup_time:
        prop.carried = True
        s = min((hand.timer - body.tuning.pickup_time) / body.tuning.pickup_time, 1.0)
        ptr.position = ptr.position + s * (carry_position(world, entity, body, prop.radius) - ptr.position)
        prop.velocity = np.zeros(6)
    _hands(world, entity, ptr.position, prop.radius)


def pickup_done(world: World, entity: Entity, brain: Brain) -> bool:
    """Reached and lifted (or the ball vanished)."""
    hand = world.get(entity, Handling)
    pickup_time = world.get(entity, PuppetBody).tuning.pickup_time
    return hand.object is None or not world.alive(hand.object) or hand.timer >= 2 * pickup_time


def update_carry(world: World, entity: Entity, brain: Brain) -> None:
    """Walk with the ball held in front of the chest."""
    body = world.get(entity, PuppetBody)
    hand = world.get(entity, Handling)
    player = world.get(entity, LocomotionPlayer)
    player.height = None
    if body.target_height > body.tuning.crouch_exit:
        hand.raised = True
    follow_stick(world, entity, body, player, speed_scale=0.8)
    if hand.object is None or not world.alive(hand.object):
        return
    prop, ptr = world.get(hand.object, Prop), world.get(hand.object, Transform)
    ptr.position = carry_position(world, entity, body, prop.radius)
    prop.carried = True
    _hands(world, entity, ptr.position, prop.radius)


def exit_carry(world: World, entity: Entity, brain: Brain) -> None:
    """Whatever comes next, physics holds the ball until PutDown takes it again (a fall drops it)."""
    hand = world.get(entity, Handling)
    if hand.object is not None and world.alive(hand.object):
        prop = world.get(hand.object, Prop)
        prop.carried, prop.placed, prop.velocity = False, True, np.zeros(6)


def enter_putdown(world: World, entity: Entity, brain: Brain) -> None:
    """Start lowering the ball: onto a bigger ball its ground spot would overlap, else onto the ground.

    The ball under it is remembered (``Handling.onto``), not its position: it may still be
    moving, and a game may re-aim to the top of a stack standing on it.
    """
    body = world.get(entity, PuppetBody)
    hand = world.get(entity, Handling)
    hand.timer = 0.0
    hand.onto = None
    if hand.object is None or not world.alive(hand.object):
        return
    prop = world.get(hand.object, Prop)
    ahead = world.get(entity, Transform).position + heading_vector(body.heading) * (
        body.tuning.front + 0.03 + prop.radius
    )
    hand.spot = np.array([ahead[0], prop.radius, ahead[2]])
    nearest = np.inf
    for e, other, otr in world.query(Prop, Transform):
        if e == hand.object or other.carried or other.radius <= prop.radius:
            continue
        gap = float(np.hypot(*(otr.position - ahead)[[0, 2]]))
        if gap < other.radius + prop.radius and gap < nearest:
            hand.onto, nearest = e, gap


def putdown_spot(world: World, hand: Handling, radius: float) -> np.ndarray:
    """Where the lowered ball goes now: on top of ``hand.onto`` if it is still there, else the ground spot."""
    under = hand.onto
    if under is not None and world.alive(under):
        top = world.get(under, Transform).position
        return top + np.array([0.0, world.get(under, Prop).radius + radius + 0.01, 0.0])
    assert hand.spot is not None  # set when the put-down began with a ball in hand
    return hand.spot


def update_putdown(world: World, entity: Entity, brain: Brain) -> None:
    """Lower the ball to its spot."""
    body = world.get(entity, PuppetBody)
    hand = world.get(entity, Handling)
    player = world.get(entity, LocomotionPlayer)
    player.speed, player.height = 0.0, body.tuning.crouch_height + 0.1
    hand.timer += world.dt
    if hand.object is None or not world.alive(hand.object):
        return
    prop, ptr = world.get(hand.object, Prop), world.get(hand.object, Transform)
    prop.carried = True
    s = min(hand.timer / body.tuning.pickup_time, 1.0)
    ptr.position = ptr.position + s * (putdown_spot(world, hand, prop.radius) - ptr.position)
    _hands(world, entity, ptr.position, prop.radius)


def putdown_done(world: World, entity: Entity, brain: Brain) -> bool:
    """The ball is at its spot."""
    return world.get(entity, Handling).timer >= world.get(entity, PuppetBody).tuning.pickup_time


def exit_putdown(world: World, entity: Entity, brain: Brain) -> None:
    """Let go: physics takes the ball again."""
    hand = world.get(entity, Handling)
    if hand.object is not None and world.alive(hand.object):
        prop = world.get(hand.object, Prop)
        prop.carried, prop.placed, prop.velocity = False, True, np.zeros(6)
        hand.left = hand.object
    hand.object = None
    hand.spot = None
    hand.onto = None


def can_roll(world: World, entity: Entity, brain: Brain) -> bool:
    """Crouch-walking into a free ball.

    The puppet's own stride decides, not the stick's speed: the stick jitters while it
    is lowered (a wheel notch slides the held point), and a puppet crouched still over
    a small ball is about to pick it up, not to push it away.
    """
    body = world.get(entity, PuppetBody)
    walking = float(world.get(entity, LocomotionPlayer).speed) > body.tuning.still_speed
    return body.held_by is not None and walking and prop_in_front(world, entity, body, body.tuning.reach) is not None


def enter_roll(world: World, entity: Entity, brain: Brain) -> None:
    """Take the ball in front."""
    body = world.get(entity, PuppetBody)
    hand = world.get(entity, Handling)
    hand.object = prop_in_front(world, entity, body, body.tuning.reach)
    hand.timer = 0.0


def update_roll(world: World, entity: Entity, brain: Brain) -> None:
    """Crouch-walk with both hands on the ball, pushing it ahead, rolling without slipping."""
    body = world.get(entity, PuppetBody)
    hand = world.get(entity, Handling)
    player = world.get(entity, LocomotionPlayer)
    t = body.tuning
    player.height = float(np.clip(body.target_height, t.crouch_height, t.crouch_exit))
    follow_stick(world, entity, body, player, speed_scale=0.9)
    if hand.object is None or not world.alive(hand.object):
        return
    prop, ptr = world.get(hand.object, Prop), world.get(hand.object, Transform)
    tr = world.get(entity, Transform)
    new = tr.position + heading_vector(body.heading) * (body.tuning.front + 0.08 + prop.radius)
    new = np.array([new[0], prop.radius, new[2]])
    moved = new - ptr.position
    moved[1] = 0.0
    dist = float(np.linalg.norm(moved))
    if dist > 1e-9:
        axis = np.cross(np.array([0.0, 1.0, 0.0]), moved / dist)
        ptr.rotation = quat.normalize(quat.mul(quat.from_axis_angle(axis, dist / prop.radius), ptr.rotation))
    velocity = moved / world.dt
    prop.velocity = np.concatenate([velocity, np.cross(np.array([0.0, 1.0, 0.0]), velocity) / prop.radius])
    ptr.position = new
    prop.carried = True
    _hands(world, entity, new, prop.radius)


def stop_rolling(world: World, entity: Entity, brain: Brain) -> bool:
    """Stood up or let go."""
    body = world.get(entity, PuppetBody)
    return body.held_by is None or body.target_height > body.tuning.crouch_exit


def exit_roll(world: World, entity: Entity, brain: Brain) -> None:
    """Leave the ball where it is, at rest."""
    hand = world.get(entity, Handling)
    if hand.object is not None and world.alive(hand.object):
        prop = world.get(hand.object, Prop)
        prop.carried, prop.placed, prop.velocity = False, True, np.zeros(6)
    hand.object = None


def wants_putdown(world: World, entity: Entity, brain: Brain) -> bool:
    """Crouching again while carrying.

    The stick is still low when the ball has just been lifted (the player crouched to
    pick it up); only a lowering *after* standing up with the ball puts it down.
    """
    return world.get(entity, Handling).raised and wants_crouch(world, entity, brain) and brain.time_in_state > 0.3


_S = PuppetState
_PICK_UP: PuppetStateDef = PuppetStateDef(
    _S.PICK_UP, enter=enter_pickup, update=update_pickup, description="hands reach a small ball and lift it"
)
_CARRY: PuppetStateDef = PuppetStateDef(
    _S.CARRY, update=update_carry, exit=exit_carry, fits=locomotion_fits, description="walk holding the ball"
)
_PUT_DOWN: PuppetStateDef = PuppetStateDef(
    _S.PUT_DOWN,
    enter=enter_putdown,
    update=update_putdown,
    exit=exit_putdown,
    description="lower the ball, onto another ball if one is in front",
)
_ROLL: PuppetStateDef = PuppetStateDef(
    _S.ROLL_SNOWBALL,
    enter=enter_roll,
    update=update_roll,
    exit=exit_roll,
    fits=locomotion_fits,
    description="crouch walk, both hands on the ball, pushing it",
)

SPEC = StateSpec(
    states=(_PICK_UP, _CARRY, _PUT_DOWN, _ROLL),
    transitions=(
        PuppetTransition(
            _S.CROUCH, _S.PICK_UP, guard=can_pick_up, priority=10, crossfade=0.2, label="still over a small ball"
        ),
        PuppetTransition(_S.CROUCH, _S.ROLL_SNOWBALL, guard=can_roll, priority=8, crossfade=0.2, label="pushes a ball"),
        PuppetTransition(_S.PICK_UP, _S.CARRY, guard=pickup_done, crossfade=0.2, label="lifted"),
        PuppetTransition(_S.CARRY, _S.PUT_DOWN, guard=wants_putdown, priority=5, crossfade=0.2, label="lowered"),
        PuppetTransition(_S.PUT_DOWN, _S.LOCOMOTION, guard=putdown_done, crossfade=0.2, label="set down"),
        PuppetTransition(
            _S.ROLL_SNOWBALL, _S.LOCOMOTION, guard=stop_rolling, priority=5, crossfade=0.25, label="stood up"
        ),
    ),
)
"""The ball-handling states and the ways into and out of them."""
