"""The snowman rules one at a time, on a bare world (no physics, no demo): fast enough for mutmut.

Each test states one rule of ``games/snowman/rules.py``; the mutation run (docs/mutation.md) is the
check that it can fail: e.g. stacking balls of equal size (``<=`` for ``<``) fails
``test_a_smaller_ball_resting_on_a_bigger_one_packs_on_centred``, a drag that overshoots to a
reversed velocity fails ``test_snow_drag_slows_a_free_ball_to_a_stop_and_no_further``.
"""

from __future__ import annotations

import numpy as np
import pytest

from engine.blend.locomotion import LocomotionPlayer
from engine.components import Grabbable, Stick, Transform
from engine.ecs import World
from engine.ragdoll.components import Prop
from engine.statemachine import Brain
from engine.statemachine.machine import State, StateMachine
from engine.statemachine.puppet import Handling, PuppetBody, PuppetMachine
from games.snowman import rules
from games.snowman.components import Snowball, Snowman, SnowmanStats, Stacked, StackWatch
from games.snowman.snow import SnowField


def world(field: SnowField | None = None) -> World:
    w = World(seed=1)
    w.insert_resource(field or SnowField(size=8.0))
    w.insert_resource(SnowmanStats())
    w.insert_resource(StackWatch())
    w.insert_resource(PuppetMachine())  # what a snowman coming alive is given as its brain
    return w


def brain(active: str) -> Brain:
    machine = StateMachine("m", [State(active), State("Other")], [], default=active)
    return Brain(machine=machine, active=active)


def on_top(w: World, lower: int, radius: float) -> int:
    """A ball of ``radius`` touching ``lower`` from above."""
    low = w.get(lower, Transform).position
    return _ball_at(w, low + np.array([0.0, w.get(lower, Prop).radius + radius, 0.0]), radius)


def _ball_at(w: World, position: np.ndarray, radius: float) -> int:
    """A ball of ``radius`` centred at ``position`` (``spawn_ball`` puts it on the ground)."""
    e = rules.spawn_ball(w, position, radius)
    w.get(e, Transform).position = np.array(position, dtype=np.float64)
    return e


def test_spawn_ball_puts_a_growing_grabbable_ball_on_the_ground() -> None:
    w = world()
    e = rules.spawn_ball(w, np.array([1.0, 5.0, 2.0]), 0.2)
    np.testing.assert_array_equal(w.get(e, Transform).position, [1.0, 0.2, 2.0])
    assert w.get(e, Prop).radius == 0.2 and w.get(e, Snowball).snow == 0.2
    np.testing.assert_array_equal(w.get(e, Snowball).last, [1.0, 0.2, 2.0])
    grab = w.get(e, Grabbable)
    assert grab.radius == pytest.approx(0.25) and grab.kind == "snowball"


def test_a_smaller_ball_resting_on_a_bigger_one_packs_on_centred() -> None:
    w = world()
    big = rules.spawn_ball(w, np.array([0.0, 0.0, 0.0]), 0.4)
    small = _ball_at(w, np.array([0.1, 0.8 + 0.25, 0.0]), 0.25)  # a little off-centre, touching
    w.get(small, Prop).velocity = np.array([0.3, 0.0, 0.0, 1.0, 0.0, 0.0])
    rules.stick_stacked_balls(w)
    assert w.get(small, Stacked).on == big
    assert w.get(small, Prop).carried and not w.get(big, Prop).carried
    np.testing.assert_array_equal(w.get(small, Prop).velocity, np.zeros(6))
    np.testing.assert_allclose(w.get(small, Transform).position, [0.0, 1.05, 0.0])
    w.get(big, Transform).position = np.array([2.0, 0.4, 1.0])  # the bottom ball is rolled away
    rules.stick_stacked_balls(w)
    np.testing.assert_allclose(w.get(small, Transform).position, [2.0, 1.05, 1.0])
    assert w.get(small, Stacked).on == big


@pytest.mark.parametrize(
    "upper,rise,stacks", [(0.4, 0.0, False), (0.41, 0.0, False), (0.25, 0.49, True), (0.25, 0.5, False)]
)
def test_only_a_smaller_ball_not_bouncing_up_packs_on(upper: float, rise: float, stacks: bool) -> None:
    w = world()
    rules.spawn_ball(w, np.zeros(3), 0.4)
    top = _ball_at(w, np.array([0.0, 0.8 + upper, 0.0]), upper)
    w.get(top, Prop).velocity = np.array([0.0, rise, 0.0, 0.0, 0.0, 0.0])
    rules.stick_stacked_balls(w)
    assert w.has(top, Stacked) is stacks and w.get(top, Prop).carried is stacks


def test_a_ball_beside_or_above_without_touching_does_not_pack_on() -> None:
    w = world()
    rules.spawn_ball(w, np.zeros(3), 0.4)
    beside = _ball_at(w, np.array([0.6, 0.2, 0.0]), 0.2)
    floating = _ball_at(w, np.array([3.0, 0.8 + 0.2 + 0.3, 0.0]), 0.2)
    rules.spawn_ball(w, np.array([3.0, 0.0, 0.0]), 0.4)
    rules.stick_stacked_balls(w)
    assert not w.has(beside, Stacked) and not w.has(floating, Stacked)


def test_a_held_ball_neither_packs_on_nor_takes_one() -> None:
    w = world()
    big = rules.spawn_ball(w, np.zeros(3), 0.4)
    small = on_top(w, big, 0.2)
    stick = w.spawn(Stick())
    w.get(stick, Stick).grabbed = small
    rules.stick_stacked_balls(w)
    assert not w.has(small, Stacked)
    w.get(stick, Stick).grabbed = big  # the bottom ball in the hand: nothing packs onto it
    rules.stick_stacked_balls(w)
    assert not w.has(small, Stacked)
    carrier = w.spawn(PuppetBody(), Handling())
    w.get(stick, Stick).grabbed = None
    w.get(carrier, Handling).object = big  # carried by a puppet: the same
    rules.stick_stacked_balls(w)
    assert not w.has(small, Stacked)
    w.get(carrier, Handling).object = None
    rules.stick_stacked_balls(w)
    assert w.get(small, Stacked).on == big


def test_a_packed_ball_comes_loose_when_its_base_goes_or_it_is_picked_up() -> None:
    w = world()
    big = rules.spawn_ball(w, np.zeros(3), 0.4)
    small = on_top(w, big, 0.2)
    rules.stick_stacked_balls(w)
    w.despawn(big)
    rules.stick_stacked_balls(w)
    prop = w.get(small, Prop)
    assert not w.has(small, Stacked) and not prop.carried and prop.placed  # handed back to physics
    np.testing.assert_array_equal(prop.velocity, np.zeros(6))
    base = rules.spawn_ball(w, np.zeros(3), 0.4)
    w.get(small, Transform).position = np.array([0.0, 1.0, 0.0])
    prop.placed = False
    rules.stick_stacked_balls(w)
    assert w.get(small, Stacked).on == base
    stick = w.spawn(Stick())
    w.get(stick, Stick).grabbed = small
    rules.stick_stacked_balls(w)
    assert not w.has(small, Stacked) and prop.carried and not prop.placed  # the stick has it: physics does not


def test_a_ball_packs_onto_one_base_only() -> None:
    w = world()
    a = rules.spawn_ball(w, np.array([-0.21, 0.0, 0.0]), 0.4)
    b = rules.spawn_ball(w, np.array([0.21, 0.0, 0.0]), 0.4)
    top = _ball_at(w, np.array([0.0, 0.4 + float(np.sqrt(0.6**2 - 0.21**2)), 0.0]), 0.2)  # touching both
    rules.stick_stacked_balls(w)
    on = w.get(top, Stacked).on
    assert on in (a, b)
    expected = w.get(on, Transform).position + np.array([0.0, 0.6, 0.0])
    np.testing.assert_allclose(w.get(top, Transform).position, expected)


def test_a_lone_ball_is_left_alone() -> None:
    w = world()
    e = _ball_at(w, np.array([0.0, 1.0, 0.0]), 0.2)
    rules.stick_stacked_balls(w)
    assert not w.has(e, Stacked) and not w.get(e, Prop).carried


def test_a_ball_rolled_over_fresh_snow_grows_in_steps() -> None:
    w = world()
    field = w.resource(SnowField)
    e = rules.spawn_ball(w, np.array([0.0, 0.0, 0.0]), 0.2)
    rules.grow_snowballs(w)  # first step: ``last`` is where it was spawned, nothing rolled
    assert w.get(e, Prop).radius == 0.2
    tr, ball, prop = w.get(e, Transform), w.get(e, Snowball), w.get(e, Prop)
    expected = SnowField(size=8.0).roll(np.array([0.0, 0.2, 0.0]), np.array([1.0, 0.2, 0.0]), 0.2)
    tr.position = np.array([1.0, 0.2, 0.0])
    rules.grow_snowballs(w)
    assert ball.snow == pytest.approx(expected) and expected - 0.2 >= rules.GROWTH_STEP
    assert prop.radius == ball.snow and w.get(e, Grabbable).radius == pytest.approx(prop.radius + 0.05)
    np.testing.assert_array_equal(ball.last, [1.0, 0.2, 0.0])
    assert field.depth_at(np.array([0.5, 0.0, 0.0])) < field.initial_depth
    before = prop.radius
    tr.position = np.array([1.0, 0.2, 0.05])  # a short roll: snow picked up, not yet a physical step
    rules.grow_snowballs(w)
    assert ball.snow > before and prop.radius == before


def test_a_ball_in_the_air_or_at_full_size_does_not_grow() -> None:
    w = world()
    e = rules.spawn_ball(w, np.zeros(3), 0.2)
    tr, prop = w.get(e, Transform), w.get(e, Prop)
    tr.position = np.array([1.0, 0.2 + 0.031, 0.0])
    rules.grow_snowballs(w)
    assert prop.radius == 0.2 and w.get(e, Snowball).snow == 0.2
    np.testing.assert_array_equal(w.get(e, Snowball).last, tr.position)  # still tracked while airborne
    tr.position = np.array([2.0, 0.2 + 0.029, 0.0])
    rules.grow_snowballs(w)
    assert prop.radius > 0.2
    big = rules.spawn_ball(w, np.array([-2.0, 0.0, 0.0]), rules.MAX_RADIUS)
    w.get(big, Transform).position = np.array([-3.0, rules.MAX_RADIUS, 0.0])
    rules.grow_snowballs(w)
    assert w.get(big, Prop).radius == rules.MAX_RADIUS and w.get(big, Snowball).snow == rules.MAX_RADIUS


def test_growth_stops_at_the_largest_ball() -> None:
    w = world(SnowField(size=8.0, initial_depth=0.5))
    e = rules.spawn_ball(w, np.zeros(3), rules.MAX_RADIUS - 0.005)
    w.get(e, Transform).position = np.array([3.0, rules.MAX_RADIUS - 0.005, 0.0])
    rules.grow_snowballs(w)
    assert w.get(e, Prop).radius == rules.MAX_RADIUS == w.get(e, Snowball).snow


def test_an_unplaced_ball_starts_tracking_without_growing() -> None:
    w = world()
    e = w.spawn(Transform(np.array([0.0, 0.2, 0.0])), Prop(radius=0.2), Snowball(), Grabbable(radius=0.25))
    rules.grow_snowballs(w)
    assert w.get(e, Prop).radius == 0.2
    np.testing.assert_array_equal(w.get(e, Snowball).last, [0.0, 0.2, 0.0])


def test_a_still_ball_does_not_grow() -> None:
    w = world()
    e = rules.spawn_ball(w, np.array([1.0, 0.0, 1.0]), 0.2)
    w.get(e, Transform).position = np.array([1.00005, 0.2, 1.0])
    rules.grow_snowballs(w)
    assert w.get(e, Snowball).snow == 0.2


def test_a_full_size_ball_leaves_the_snow_alone() -> None:
    w = world()
    before = w.resource(SnowField).depth.copy()
    e = rules.spawn_ball(w, np.zeros(3), rules.MAX_RADIUS)
    w.get(e, Transform).position = np.array([2.0, rules.MAX_RADIUS, 0.0])
    rules.grow_snowballs(w)
    np.testing.assert_array_equal(w.resource(SnowField).depth, before)


def test_snow_drag_slows_a_free_ball_to_a_stop_and_no_further() -> None:
    w = world()
    e = rules.spawn_ball(w, np.zeros(3), 0.2)
    prop = w.get(e, Prop)
    prop.velocity = np.array([3.0, 0.0, 4.0, 1.0, 2.0, 3.0])
    rules.snow_drag(w)
    keep = 1.0 - rules.SNOW_DRAG * w.dt / 5.0
    np.testing.assert_allclose(prop.velocity, np.array([3.0, 0.0, 4.0, 1.0, 2.0, 3.0]) * keep)
    assert prop.placed
    prop.velocity = np.array([0.01, 0.0, 0.0, 0.0, 0.0, 0.0])
    rules.snow_drag(w)
    np.testing.assert_array_equal(prop.velocity, np.zeros(6))


def test_snow_drag_takes_the_speed_as_numpys_norm_to_the_bit() -> None:
    """The recordings replay bit for bit only if the rules' arithmetic stays what it was: the kept fraction is
    ``1 - step / np.linalg.norm(v)`` exactly. Broken once with ``math.hypot`` for the speed (it rounds
    differently in about one ball of five; 7 of these 64 velocities then differ)."""
    w = world()
    rng = np.random.default_rng(3)
    given = rng.normal(size=(64, 6))  # speeds just above a step's loss, where a last bit of the speed shows
    given *= rng.uniform(0.09, 0.3, (64, 1)) / np.linalg.norm(given[:, :3], axis=1, keepdims=True)
    balls = [rules.spawn_ball(w, np.array([0.1 * i, 0.0, 0.0]), 0.2) for i in range(len(given))]
    for e, v in zip(balls, given, strict=True):
        w.get(e, Prop).velocity = v.copy()
    rules.snow_drag(w)
    step = rules.SNOW_DRAG * w.dt
    for e, v in zip(balls, given, strict=True):
        np.testing.assert_array_equal(w.get(e, Prop).velocity, v * max(0.0, 1.0 - step / float(np.linalg.norm(v[:3]))))


def test_snow_drag_slows_every_free_ball_whatever_comes_before_it() -> None:
    w = world()
    rest = rules.spawn_ball(w, np.array([4.0, 0.0, 0.0]), 0.2)
    carried = rules.spawn_ball(w, np.array([2.0, 0.0, 0.0]), 0.2)
    w.get(carried, Prop).carried = True
    moving = rules.spawn_ball(w, np.zeros(3), 0.2)
    w.get(moving, Prop).velocity = np.array([1.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    rules.snow_drag(w)
    assert w.get(moving, Prop).velocity[0] < 1.0 and not w.get(rest, Prop).placed


def test_snow_drag_spares_carried_held_airborne_and_resting_balls() -> None:
    w = world()
    v = np.array([1.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    carried = rules.spawn_ball(w, np.zeros(3), 0.2)
    w.get(carried, Prop).carried = True
    held = rules.spawn_ball(w, np.array([1.0, 0.0, 0.0]), 0.2)
    w.get(w.spawn(Stick()), Stick).grabbed = held
    air = rules.spawn_ball(w, np.array([2.0, 0.0, 0.0]), 0.2)
    w.get(air, Transform).position[1] = 0.2 + 0.031
    low = rules.spawn_ball(w, np.array([3.0, 0.0, 0.0]), 0.2)
    w.get(low, Transform).position[1] = 0.2 + 0.029
    for e in (carried, held, air, low):
        w.get(e, Prop).velocity = v.copy()
    rest = rules.spawn_ball(w, np.array([4.0, 0.0, 0.0]), 0.2)
    w.get(rest, Prop).velocity = np.array([0.0, 0.0, 0.00009, 5.0, 0.0, 0.0])
    rules.snow_drag(w)
    for e in (carried, held, air):
        np.testing.assert_array_equal(w.get(e, Prop).velocity, v)
        assert not w.get(e, Prop).placed
    assert w.get(low, Prop).velocity[0] < 1.0 and w.get(low, Prop).placed
    assert w.get(rest, Prop).velocity[3] == 5.0 and not w.get(rest, Prop).placed


def test_every_puppet_putting_down_is_aimed() -> None:
    w = world()
    bottom = rules.spawn_ball(w, np.zeros(3), 0.5)
    middle = on_top(w, bottom, 0.35)
    rules.stick_stacked_balls(w)
    w.spawn(PuppetBody(), Handling(onto=bottom), brain("Walk"))
    held = rules.spawn_ball(w, np.array([3.0, 0.0, 0.0]), 0.2)
    puppet = w.spawn(PuppetBody(), Handling(object=held, onto=bottom), brain("PutDown"))
    rules.aim_putdown_on_stacks(w)
    assert w.get(puppet, Handling).onto == middle


def test_putting_a_ball_down_on_a_stack_aims_at_its_top() -> None:
    w = world()
    bottom = rules.spawn_ball(w, np.zeros(3), 0.5)
    middle = on_top(w, bottom, 0.35)
    rules.stick_stacked_balls(w)
    held = rules.spawn_ball(w, np.array([3.0, 0.0, 0.0]), 0.2)
    puppet = w.spawn(PuppetBody(), Handling(object=held, onto=bottom), brain("PutDown"))
    rules.aim_putdown_on_stacks(w)
    assert w.get(puppet, Handling).onto == middle
    w.get(puppet, Handling).onto = bottom
    w.get(held, Prop).radius = 0.35  # not smaller than the top: aim stays at the base
    rules.aim_putdown_on_stacks(w)
    assert w.get(puppet, Handling).onto == bottom


@pytest.mark.parametrize("case", ["other state", "no stack", "nothing held", "held gone"])
def test_putdown_aim_is_left_alone_outside_putting_down_on_a_stack(case: str) -> None:
    w = world()
    bottom = rules.spawn_ball(w, np.zeros(3), 0.5)
    on_top(w, bottom, 0.35)
    rules.stick_stacked_balls(w)
    held = rules.spawn_ball(w, np.array([3.0, 0.0, 0.0]), 0.2)
    loose = rules.spawn_ball(w, np.array([-3.0, 0.0, 0.0]), 0.5)
    aim = loose if case == "no stack" else bottom
    hand = Handling(object=None if case == "nothing held" else held, onto=aim)
    puppet = w.spawn(PuppetBody(), hand, brain("Walk" if case == "other state" else "PutDown"))
    if case == "held gone":
        w.despawn(held)
    rules.aim_putdown_on_stacks(w)
    assert w.get(puppet, Handling).onto == aim


def test_climbing_a_stack_stops_below_the_held_ball() -> None:
    """The held ball itself still counted as packed on the stack is not a target."""
    w = world()
    bottom = rules.spawn_ball(w, np.zeros(3), 0.5)
    middle = on_top(w, bottom, 0.35)
    rules.stick_stacked_balls(w)
    held = on_top(w, middle, 0.2)
    w.add(held, Stacked(on=middle))
    puppet = w.spawn(PuppetBody(), Handling(object=held, onto=bottom), brain("PutDown"))
    rules.aim_putdown_on_stacks(w)
    assert w.get(puppet, Handling).onto == middle


def crouch_walker(w: World) -> int:
    """A puppet held by a stick, crouch-walking along +Z for long enough to pack a ball."""
    b = PuppetBody(held_by=99, speed=0.5, heading=0.0)
    br = brain("Crouch")
    br.time_in_state = 0.5
    return w.spawn(b, br, Transform(np.array([0.0, 0.0, 0.0])), LocomotionPlayer(speed=0.5))


def test_a_crouch_walking_puppet_packs_a_ball_in_front_on_fresh_snow() -> None:
    w = world()
    p = crouch_walker(w)
    rules.start_snowballs(w)
    balls = w.query(Snowball, Prop, Transform)
    assert len(balls) == 1 and w.resource(SnowmanStats).balls_started == 1
    _, _, prop, tr = balls[0]
    front = w.get(p, PuppetBody).tuning.front
    assert prop.radius == rules.START_RADIUS
    np.testing.assert_allclose(tr.position, [0.0, rules.START_RADIUS, front + rules.START_GAP + rules.START_RADIUS])
    rules.start_snowballs(w)  # the new ball is in front now: no second one
    assert len(w.query(Snowball)) == 1


@pytest.mark.parametrize("change", ["state", "not held", "slow body", "slow player", "too soon", "bare snow", "full"])
def test_no_ball_is_started_unless_every_condition_holds(change: str) -> None:
    w = world()
    p = crouch_walker(w)
    body, br, player = w.get(p, PuppetBody), w.get(p, Brain), w.get(p, LocomotionPlayer)
    if change == "state":
        br.active = "Other"
    elif change == "not held":
        body.held_by = None
    elif change == "slow body":
        body.speed = 0.29
    elif change == "slow player":
        player.speed = 0.29
    elif change == "too soon":
        br.time_in_state = 0.39
    elif change == "bare snow":
        w.resource(SnowField).depth[:] = 0.0
    else:
        for i in range(rules.MAX_BALLS):
            rules.spawn_ball(w, np.array([-3.0, 0.0, -3.0 + 0.25 * i]), 0.1)
    before = len(w.query(Snowball))
    rules.start_snowballs(w)
    assert len(w.query(Snowball)) == before and w.resource(SnowmanStats).balls_started == 0


@pytest.mark.parametrize("which", ["body", "player", "time"])
def test_the_thresholds_of_starting_a_ball_are_inclusive(which: str) -> None:
    w = world()
    p = crouch_walker(w)
    if which == "body":
        w.get(p, PuppetBody).speed = 0.3
    elif which == "player":
        w.get(p, LocomotionPlayer).speed = 0.3
    else:
        w.get(p, Brain).time_in_state = 0.4
    rules.start_snowballs(w)
    assert len(w.query(Snowball)) == 1


def test_each_puppet_may_start_a_ball_up_to_the_most_balls() -> None:
    w = world()
    for i in range(rules.MAX_BALLS - 3):
        rules.spawn_ball(w, np.array([-3.0, 0.0, -3.0 + 0.25 * i]), 0.1)
    idle = crouch_walker(w)
    w.get(idle, Brain).active = "Other"  # skipped: the others still get their turn
    w.get(idle, Transform).position = np.array([3.0, 0.0, -2.0])
    blocked = crouch_walker(w)
    w.get(blocked, Transform).position = np.array([2.0, 0.0, -2.0])
    rules.spawn_ball(w, np.array([2.0, 0.0, -2.0 + 0.6]), 0.1)  # a ball half a metre ahead: in its way
    bare = crouch_walker(w)
    w.get(bare, Transform).position = np.array([-3.5, 0.0, 3.0])
    w.resource(SnowField).depth[:, :] = np.where(np.arange(80)[:, None] < 10, 0.0, 0.04)  # x < -3 m is bare
    for x in (0.0, 1.0, -1.0):
        q = crouch_walker(w)
        w.get(q, Transform).position = np.array([x, 0.0, 0.0])
    rules.start_snowballs(w)
    assert len(w.query(Snowball)) == rules.MAX_BALLS  # two started (22 → 24), not three
    assert w.resource(SnowmanStats).balls_started == 2


@pytest.mark.parametrize("gap,starts", [(0.9, False), (1.5, True)])
def test_a_ball_within_a_metre_ahead_stops_a_new_one(gap: float, starts: bool) -> None:
    w = world()
    p = crouch_walker(w)
    rules.spawn_ball(w, np.array([0.0, 0.0, gap + 0.1]), 0.1)
    rules.start_snowballs(w)
    assert (w.resource(SnowmanStats).balls_started == 1) is starts and w.alive(p)


def stack(w: World, radii: list[float], x: float = 0.0, z: float = 0.0) -> list[int]:
    ids = [rules.spawn_ball(w, np.array([x, 0.0, z]), radii[0])]
    for r in radii[1:]:
        ids.append(on_top(w, ids[-1], r))
    return ids


def test_a_stack_that_stands_still_long_enough_comes_alive(capsys: pytest.CaptureFixture[str]) -> None:
    w = world()
    ids = stack(w, [0.5, 0.35, 0.2], x=3.0, z=4.0)
    for _ in range(rules.STILL_FRAMES - 1):
        rules.assemble_snowmen(w)
    assert all(w.alive(e) for e in ids) and w.resource(StackWatch).frames == {tuple(ids): rules.STILL_FRAMES - 1}
    rules.assemble_snowmen(w)
    assert not any(w.alive(e) for e in ids) and w.resource(SnowmanStats).built == 1
    assert w.resource(StackWatch).frames == {}
    ((e, man, body),) = w.query(Snowman, PuppetBody)
    assert (man.shape.bottom, man.shape.middle, man.shape.head) == (0.5, 0.35, 0.2) and man.number == 1
    assert body.heading == pytest.approx(float(np.arctan2(-3.0, -4.0)))  # it faces the middle of the field
    assert w.get(e, Grabbable).radius == pytest.approx(0.6)
    assert capsys.readouterr().out == "snowman 1 came alive (3 balls: 0.50, 0.35, 0.20 m)\n"
    assert rules.snowmen_standing(w) == 1
    w.get(e, Brain).active = "Ragdoll"
    assert rules.snowmen_standing(w) == 0
    w.get(e, Brain).active = "GetUp"
    assert rules.snowmen_standing(w) == 0


def test_a_two_ball_snowman_needs_a_head_sized_top() -> None:
    w = world()
    headless = stack(w, [0.5, 0.31])
    fine = stack(w, [0.5, 0.3], x=3.0)
    for _ in range(rules.STILL_FRAMES):
        rules.assemble_snowmen(w)
    assert all(w.alive(e) for e in headless) and not any(w.alive(e) for e in fine)
    assert w.resource(StackWatch).headless == 1
    ((_, man),) = w.query(Snowman)
    assert man.shape.middle is None and (man.shape.bottom, man.shape.head) == (0.5, 0.3)


def test_a_snowman_near_the_middle_faces_forward() -> None:
    w = world()
    stack(w, [0.5, 0.3], x=0.3, z=0.3)
    for _ in range(rules.STILL_FRAMES):
        rules.assemble_snowmen(w)
    ((_, body),) = w.query(PuppetBody)
    assert body.heading == 0.0


def test_a_moving_or_held_stack_does_not_count_and_starts_again() -> None:
    w = world()
    ids = stack(w, [0.5, 0.3])
    for _ in range(5):
        rules.assemble_snowmen(w)
    w.get(ids[0], Prop).velocity = np.array([0.0, 0.0, 0.2, 0.0, 0.0, 0.0])
    rules.assemble_snowmen(w)
    assert w.resource(StackWatch).frames == {}
    w.get(ids[0], Prop).velocity = np.array([0.0, 0.0, 0.19, 9.0, 9.0, 9.0])
    rules.assemble_snowmen(w)
    assert w.resource(StackWatch).frames == {tuple(ids): 1}
    stick = w.spawn(Stick())
    w.get(stick, Stick).grabbed = ids[1]
    rules.assemble_snowmen(w)
    assert w.resource(StackWatch).frames == {}


def test_a_carried_ball_counts_only_when_packed_on_the_stack() -> None:
    w = world()
    ids = stack(w, [0.5, 0.3])
    w.get(ids[1], Prop).carried = True  # carried by something else than the stack: not part of it
    rules.assemble_snowmen(w)
    assert w.resource(StackWatch).frames == {}
    w.add(ids[1], Stacked(on=ids[0]))  # packed on by the stacking rule
    rules.assemble_snowmen(w)
    assert w.resource(StackWatch).frames == {tuple(ids): 1}


def test_packed_balls_stay_packed_and_follow_step_after_step() -> None:
    w = world()
    gone = rules.spawn_ball(w, np.array([-2.0, 0.0, 0.0]), 0.4)
    loose = on_top(w, gone, 0.2)
    base = rules.spawn_ball(w, np.zeros(3), 0.4)
    top = on_top(w, base, 0.2)
    rules.stick_stacked_balls(w)
    assert w.get(loose, Stacked).on == gone and w.get(top, Stacked).on == base  # two stacks in one step
    w.despawn(gone)  # the first packed ball comes loose: the second is still carried along
    w.get(base, Transform).position = np.array([1.0, 0.4, 0.0])
    rules.stick_stacked_balls(w)
    prop = w.get(top, Prop)
    assert not w.has(loose, Stacked) and prop.carried and prop.velocity.shape == (6,) and not prop.velocity.any()
    np.testing.assert_allclose(w.get(top, Transform).position, [1.0, 1.0, 0.0])


def test_how_far_from_touching_and_off_axis_a_ball_may_rest() -> None:
    w = world()
    near = rules.spawn_ball(w, np.array([-3.0, 0.0, 0.0]), 0.4)
    pressed = _ball_at(w, np.array([-3.0, 0.4 + 0.6 * 1.08, 0.0]), 0.2)  # 8 % further than touching
    side = rules.spawn_ball(w, np.array([3.0, 0.0, 0.0]), 0.4)
    off = 0.8 * 0.4  # beyond 0.6 of the lower radius to the side
    askew = _ball_at(w, np.array([3.0 + off, 0.4 + float(np.sqrt(0.6**2 - off**2)), 0.0]), 0.2)
    rules.stick_stacked_balls(w)
    assert w.get(pressed, Stacked).on == near and not w.has(askew, Stacked) and side != near


def test_only_free_balls_pack_on_and_the_others_do_not_stop_them() -> None:
    w = world()
    held_base = rules.spawn_ball(w, np.array([-0.21, 0.0, 0.0]), 0.4)
    free_base = rules.spawn_ball(w, np.array([0.21, 0.0, 0.0]), 0.4)
    w.get(w.spawn(Stick()), Stick).grabbed = held_base
    top = _ball_at(w, np.array([0.0, 0.4 + float(np.sqrt(0.6**2 - 0.21**2)), 0.0]), 0.2)
    carried_base = rules.spawn_ball(w, np.array([3.0, 0.0, 0.0]), 0.4)
    carried = on_top(w, carried_base, 0.2)
    w.get(carried, Prop).carried = True  # carried by something else: not packed on
    rules.stick_stacked_balls(w)
    assert w.get(top, Stacked).on == free_base and not w.has(carried, Stacked)


def test_headless_stacks_are_all_counted() -> None:
    w = world()
    stack(w, [0.5, 0.4])
    stack(w, [0.5, 0.45], x=3.0)
    rules.assemble_snowmen(w)
    assert w.resource(StackWatch).headless == 2


def test_snowmen_are_numbered_and_stand_where_their_bottom_ball_was(capsys: pytest.CaptureFixture[str]) -> None:
    w = world()
    for x in (-2.0, 2.0):
        bottom = rules.spawn_ball(w, np.array([x, 0.0, 1.0]), 0.5)
        _ball_at(w, np.array([x + 0.15, 0.5 + float(np.sqrt(0.8**2 - 0.15**2)), 1.0]), 0.3)  # a little askew
        for _ in range(rules.STILL_FRAMES):
            rules.assemble_snowmen(w)
        assert not w.alive(bottom)
    men = sorted((man.number, tr.position[0], tr.position[2]) for _, man, tr in w.query(Snowman, Transform))
    assert men == [(1, -2.0, 1.0), (2, 2.0, 1.0)] and w.resource(SnowmanStats).built == 2
    assert capsys.readouterr().out.splitlines()[1] == "snowman 2 came alive (2 balls: 0.50, 0.30 m)"


def test_a_snowman_a_metre_from_the_middle_faces_it() -> None:
    w = world()
    stack(w, [0.5, 0.3], x=0.6, z=0.8)
    for _ in range(rules.STILL_FRAMES):
        rules.assemble_snowmen(w)
    ((_, body),) = w.query(PuppetBody)
    assert body.heading == pytest.approx(float(np.arctan2(-0.6, -0.8)))
