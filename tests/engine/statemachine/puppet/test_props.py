"""A ball held by the MotionStick follows the tip; let go, physics takes it back with the stick's velocity."""

import numpy as np

from engine.components import Grabbable, Stick, Transform
from engine.ecs import World
from engine.ragdoll.components import Prop
from engine.statemachine.puppet.props import held_props_system


def _scene() -> tuple[World, int, int]:
    world = World(seed=1)
    ball = world.spawn(Transform(np.array([0.0, 0.2, 0.0])), Prop(radius=0.2), Grabbable(radius=0.25))
    world.spawn(Transform(np.array([1.0, 0.4, 0.0])), Prop(radius=0.4), Grabbable(radius=0.45))
    stick_entity = world.spawn(Stick())
    world.flush()
    world.get(stick_entity, Stick).grabbed = ball
    return world, ball, stick_entity


def test_held_ball_follows_the_tip_and_is_let_go_on_release():
    world, ball, s = _scene()
    stick = world.get(s, Stick)
    stick.tip = np.array([0.0, 1.0, 0.0])
    held_props_system(world)
    prop, tr = world.get(ball, Prop), world.get(ball, Transform)
    assert prop.carried and np.allclose(tr.position, [0.0, 1.0, 0.0])
    stick.tip = np.array([0.1, 1.0, 0.0])
    held_props_system(world)
    assert np.allclose(prop.velocity[:3], [0.1 / world.dt, 0.0, 0.0])
    stick.grabbed, stick.released = None, ball
    held_props_system(world)
    assert not prop.carried and prop.placed  # physics owns it again
    assert np.allclose(prop.velocity[:3], [0.1 / world.dt, 0.0, 0.0])  # thrown with the stick's velocity


def test_a_release_of_something_else_leaves_a_carried_ball_alone():
    world, ball, s = _scene()
    stick = world.get(s, Stick)
    held_props_system(world)
    stick.grabbed, stick.released = None, ball + 100
    held_props_system(world)
    assert world.get(ball, Prop).carried


def test_held_ball_slides_over_another_instead_of_sinking_into_it():
    world, ball, s = _scene()
    world.get(s, Stick).tip = np.array([1.0, 0.5, 0.0])  # inside the big ball
    held_props_system(world)
    gap = np.linalg.norm(world.get(ball, Transform).position - np.array([1.0, 0.4, 0.0]))
    assert gap >= 0.6
