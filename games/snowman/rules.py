"""The snowman game's rules (the ``rules`` stage): snow, snowballs, snowmen.

1. **Growing**: every snowball that rolls over fresh snow picks it up
   (:class:`~games.snowman.snow.SnowField`) and its radius grows by volume.
2. **Starting a ball**: a puppet crouch-walking on fresh snow with no ball in front
   packs a new small ball in front of its hands; the brain then rolls it.
3. **Snow drag**: a free ball rolling on the ground ploughs through the snow and
   slows down at ``SNOW_DRAG`` m/s² (rigid spheres on a plane would roll on for ever).
4. **Building**: two or three balls stacked largest at the bottom that stand still
   for half a second come alive as a snowman puppet (:mod:`~games.snowman.alive`).
   The top of a two-ball stack must be head-sized (at most ``HEAD_RATIO`` of the ball
   under it); a bigger one is a middle and the stack waits for its head.
"""

from __future__ import annotations

import math

import numpy as np

from engine.blend.locomotion import LocomotionPlayer
from engine.components import Grabbable, Stick, Transform
from engine.ecs import World
from engine.ragdoll.components import Prop
from engine.statemachine import Brain
from engine.statemachine.puppet import Handling, PuppetBody, PuppetState
from engine.statemachine.puppet.senses import heading_vector, prop_in_front
from games.snowman.alive import bring_to_life
from games.snowman.assembly import Ball, find_snowmen, resting_matrix
from games.snowman.components import Snowball, Snowman, SnowmanStats, Stacked, StackWatch
from games.snowman.rig import SnowmanShape
from games.snowman.snow import SnowField

__all__ = [
    "stick_stacked_balls",
    "grow_snowballs",
    "start_snowballs",
    "assemble_snowmen",
    "spawn_ball",
    "snow_drag",
    "aim_putdown_on_stacks",
    "snowmen_standing",
    "MAX_RADIUS",
    "MAX_BALLS",
    "SNOW_DRAG",
    "HEAD_RATIO",
]

MAX_RADIUS = 0.6
MAX_BALLS = 24
START_RADIUS = 0.11
START_GAP = 0.18  # beyond the body's front
GROWTH_STEP = 0.01
STILL_FRAMES = 30
SNOW_DRAG = 5.0
HEAD_RATIO = 0.6


def spawn_ball(world: World, position: np.ndarray, radius: float) -> int:
    """A snowball entity: physical, grabbable, growing."""
    pos = np.array([position[0], radius, position[2]], dtype=np.float64)
    return world.spawn(
        Transform(pos),
        Prop(radius=radius),
        Snowball(last=pos.copy(), snow=radius),
        Grabbable(radius=radius + 0.05, kind="snowball"),
    )


def _held(world: World) -> set[int]:
    return {s.grabbed for _, s in world.query(Stick) if s.grabbed is not None} | {
        h.object for _, h in world.query(Handling) if h.object is not None
    }


def stick_stacked_balls(world: World) -> None:
    """A ball that comes to rest on a bigger one packs onto it, centred, and stays there.

    Real snowballs squash where they touch and hold; rigid spheres would roll off, so
    the rule takes the upper ball out of the physics (``carried``) and keeps it on top
    of the lower one, wherever that one goes.
    """
    held = _held(world)
    balls = {e: (prop, tr) for e, _, prop, tr in world.query(Snowball, Prop, Transform)}
    for e, stacked in list(world.query(Stacked)):
        pair = balls.get(e)
        if pair is None or e in held or stacked.on not in balls:
            world.remove(e, Stacked)
            if pair is not None and e not in held:
                pair[0].carried, pair[0].placed, pair[0].velocity = False, True, np.zeros(6)
            continue
        prop, tr = pair
        lower_prop, lower_tr = balls[stacked.on]
        tr.position = lower_tr.position + np.array([0.0, lower_prop.radius + prop.radius, 0.0])
        prop.carried, prop.velocity = True, np.zeros(6)
    keys = list(balls)
    if len(keys) < 2:
        return
    centers = np.array([balls[k][1].position for k in keys])
    radii = np.array([balls[k][0].radius for k in keys])
    on = resting_matrix(centers, radii, gap=0.1, off_axis=0.6) & (radii[:, None] < radii[None, :])
    rows, cols = np.nonzero(on)  # row-major: each ball's candidates in order, balls resting on none skipped
    candidates: dict[int, list[int]] = {}
    for i, j in zip(rows.tolist(), cols.tolist(), strict=True):
        candidates.setdefault(i, []).append(j)
    for i, below in candidates.items():
        e = keys[i]
        prop, tr = balls[e]
        if e in held or world.has(e, Stacked) or prop.carried or prop.velocity[1] >= 0.5:
            continue
        for j in below:
            o = keys[j]
            if o in held:
                continue
            tr.position = balls[o][1].position + np.array([0.0, balls[o][0].radius + prop.radius, 0.0])
            world.add(e, Stacked(on=o))
            prop.carried, prop.velocity = True, np.zeros(6)
            break


def grow_snowballs(world: World) -> None:
    """Balls touching the ground grow by the fresh snow they roll over."""
    field = world.resource(SnowField)
    for _, ball, prop, tr, grab in world.query(Snowball, Prop, Transform, Grabbable):
        here = tr.position.copy()
        (x, y, z), (last_x, last_y, last_z) = here.tolist(), ball.last.tolist()  # floats: numpy's scalars cost more
        finite = math.isfinite(last_x) and math.isfinite(last_y) and math.isfinite(last_z)
        rolling = finite and y - prop.radius < 0.03 and prop.radius < MAX_RADIUS
        if rolling and float(np.hypot(x - last_x, z - last_z)) > 1e-4:
            ball.snow = min(field.roll(ball.last, here, max(ball.snow, prop.radius)), MAX_RADIUS)
            if ball.snow - prop.radius >= GROWTH_STEP or ball.snow >= MAX_RADIUS:
                prop.radius = ball.snow
                grab.radius = prop.radius + 0.05
        ball.last = here


def snow_drag(world: World) -> None:
    """Free balls on the ground lose ``SNOW_DRAG`` m/s of speed per second to the snow.

    The new velocity is handed to physics with ``Prop.placed`` (the pose stays the one
    physics wrote), so a ball let go while moving rolls a short way and stops.
    """
    held = _held(world)
    step = SNOW_DRAG * world.dt
    for e, _, prop, tr in world.query(Snowball, Prop, Transform):
        if prop.carried or e in held or tr.position[1] - prop.radius > 0.03:
            continue
        speed = _speed(prop)
        if speed < 1e-4:
            continue
        keep = max(0.0, 1.0 - step / speed)
        prop.velocity = prop.velocity * keep
        prop.placed = True


def aim_putdown_on_stacks(world: World) -> None:
    """A puppet putting a ball down onto a stack puts it on the stack's top ball.

    The brain aims at the first free ball in front (``Handling.onto``); balls already
    packed on it are ``carried`` and invisible to it, so it would press the new ball
    into them. This rule climbs the stack to its top and aims there while the top ball
    is still the bigger one.
    """
    on = {s.on: e for e, s in world.query(Stacked)}
    for _, hand, brain in world.query(Handling, Brain):
        base, ball = hand.onto, hand.object
        if brain.active != PuppetState.PUT_DOWN or base not in on or ball is None or not world.alive(ball):
            continue
        top = base
        while top in on and on[top] != ball:
            top = on[top]
        if world.get(top, Prop).radius > world.get(ball, Prop).radius:
            hand.onto = top


def start_snowballs(world: World) -> None:
    """A crouch-walking puppet with nothing in front packs a new ball on fresh snow."""
    field = world.resource(SnowField)
    stats = world.resource(SnowmanStats)
    count = len(world.query(Snowball))
    for e, body, brain, tr, player in world.query(PuppetBody, Brain, Transform, LocomotionPlayer):
        # The puppet itself must be under way (not only the stick): a ball packed at the
        # feet of a puppet still crouching in place lands in its hands' collision shapes.
        if (
            brain.active != PuppetState.CROUCH
            or body.held_by is None
            or body.speed < 0.3
            or player.speed < 0.3
            or brain.time_in_state < 0.4
        ):
            continue
        if count >= MAX_BALLS or prop_in_front(world, e, body, 1.0) is not None:
            continue
        spot = tr.position + heading_vector(body.heading) * (body.tuning.front + START_GAP + START_RADIUS)
        if field.depth_at(spot) <= 0.0:
            continue
        spawn_ball(world, spot, START_RADIUS)
        stats.balls_started += 1
        count += 1


def assemble_snowmen(world: World) -> None:
    """Stacks that stood still long enough come alive."""
    watch = world.resource(StackWatch)
    stats = world.resource(SnowmanStats)
    held = _held(world)
    still = [
        Ball(e, tr.position.copy(), prop.radius)
        for e, _, prop, tr in world.query(Snowball, Prop, Transform)
        if e not in held and (not prop.carried or world.has(e, Stacked)) and _speed(prop) < 0.2
    ]
    seen: dict[tuple[int, ...], int] = {}
    watch.headless = 0
    for stack in find_snowmen(still):
        if len(stack) == 2 and stack[1].radius > HEAD_RATIO * stack[0].radius:
            watch.headless += 1
            continue
        key = tuple(b.entity for b in stack)
        seen[key] = watch.frames.get(key, 0) + 1
        if seen[key] >= STILL_FRAMES:
            radii = [b.radius for b in stack]
            shape = SnowmanShape(radii[0], radii[1] if len(radii) == 3 else None, radii[-1])
            stats.built += 1
            bottom = stack[0].center
            heading = float(np.arctan2(-bottom[0], -bottom[2])) if np.hypot(bottom[0], bottom[2]) > 0.5 else 0.0
            snowman = bring_to_life(world, shape, bottom, heading, stats.built)
            world.get(snowman, Grabbable).radius = shape.bottom + 0.1
            for b in stack:
                world.despawn(b.entity)
            del seen[key]
            print(f"snowman {stats.built} came alive ({len(stack)} balls: {', '.join(f'{r:.2f}' for r in radii)} m)")
    watch.frames = seen


def _speed(prop: Prop) -> float:
    """A prop's speed: ``np.linalg.norm`` of its linear velocity to the bit (the square root of the same dot
    product) without the call's checks, which cost more than the arithmetic for one ball."""
    v = prop.velocity[:3]
    return math.sqrt(v.dot(v))


def snowmen_standing(world: World) -> int:
    """How many snowmen are alive and on their feet (not a ragdoll)."""
    return sum(
        1
        for _, _, brain in world.query(Snowman, Brain)
        if brain.active not in (PuppetState.RAGDOLL, PuppetState.GET_UP)
    )
