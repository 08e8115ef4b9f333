"""Animated puppets cost no dynamics: out of the model alone, in it when something simulated is near."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from engine.app import App
from engine.clip import Clip
from engine.components import LocalPose, Transform
from engine.ecs import World
from engine.fk import forward_kinematics
from engine.ragdoll import PhysicsWorld, Ragdoll, RagdollMode, default_profile, spawn_snowball
from engine.ragdoll._islands import ENTER, LEAVE, near_simulated, reach
from engine.ragdoll.components import Prop
from engine.skeleton import Skeleton


def _walk_along_z(app: App, e: int, clip: Clip, speed: float) -> None:
    def animate(world: World) -> None:
        p = clip.sample(world.time)
        lp = world.get(e, LocalPose)
        lp.root = p.root + np.array([0.0, 0.0, speed * world.time])
        lp.rotations = p.rotations

    app.add_system("animation", animate)


def test_reach_holds_the_rest_pose_and_a_raised_arm(skeleton: Skeleton) -> None:
    prof = default_profile(skeleton)
    r = reach(skeleton, prof, skeleton.offsets)
    pos, _ = forward_kinematics(skeleton, np.zeros(3), np.tile([1.0, 0, 0, 0], (skeleton.num_joints, 1)))
    assert np.linalg.norm(pos, axis=1).max() < r < 3.0


def test_near_simulated_has_hysteresis() -> None:
    c, r = np.zeros((2, 3)), np.ones(2)
    src, src_r = np.array([[2.0 + 0.5 * (ENTER + LEAVE), 0.0, 0.0]]), np.array([1.0])
    # between the two limits: the one inside stays, the one outside does not join
    np.testing.assert_array_equal(near_simulated(c, r, src, src_r, np.array([True, False])), [True, False])
    assert not near_simulated(c, r, np.zeros((0, 3)), np.zeros(0), np.array([True, True])).any()


def test_a_lone_animated_puppet_is_not_simulated(make_app: Callable[..., tuple[App, int]], walk_clip: Clip) -> None:
    start = walk_clip.sample(0.0)
    app, e = make_app(start.root, start.rotations, mode=RagdollMode.ANIMATED)
    _walk_along_z(app, e, walk_clip, 1.2)
    app.run_steps(10)
    pw = app.world.resource(PhysicsWorld)
    assert not pw.in_model(e) and pw.model is None
    assert abs(pw.root_velocity(e)[2] - 1.2) < 0.1  # its target's velocity


def test_an_animated_puppet_still_shoves_a_ball_in_its_way(
    make_app: Callable[..., tuple[App, int]], walk_clip: Clip
) -> None:
    start = walk_clip.sample(0.0)
    app, e = make_app(start.root, start.rotations, mode=RagdollMode.ANIMATED)
    _walk_along_z(app, e, walk_clip, 1.2)
    ball = spawn_snowball(app.world, [0.0, 0.15, 3.0], 0.15)
    pw = app.world.resource(PhysicsWorld)
    app.run_steps(5)
    assert not pw.in_model(e)  # the ball is far
    joined = False
    for _ in range(240):
        app.step()
        joined |= pw.in_model(e)
    assert joined
    assert app.world.get(ball, Transform).position[2] > 3.3  # pushed along the walk
    assert np.isfinite(app.world.get(ball, Prop).velocity).all()


def test_going_limp_keeps_the_walk_s_momentum(make_app: Callable[..., tuple[App, int]], walk_clip: Clip) -> None:
    start = walk_clip.sample(0.0)
    app, e = make_app(start.root, start.rotations, mode=RagdollMode.ANIMATED)
    _walk_along_z(app, e, walk_clip, 2.0)
    app.run_steps(20)
    pw = app.world.resource(PhysicsWorld)
    assert not pw.in_model(e)
    app.world.get(e, Ragdoll).set_mode(RagdollMode.LIMP, immediate=True)
    app.step()
    assert pw.in_model(e)
    assert pw.root_velocity(e)[2] > 1.0  # it joined the model moving, not at rest


def test_a_limp_neighbour_pulls_in_only_a_puppet_its_bodies_come_near(skeleton: Skeleton) -> None:
    """Reach spheres (any pose) of puppets 1.6 m apart overlap, their posed capsules do not: the
    animated neighbour stays out. At 0.7 m (rest-pose boxes 0.44 m wide, 0.26 m of clearance: more
    than ENTER, less than the 0.4 m it was) it still stays out; at 0.5 m (0.06 m) it joins.
    (Breaking it: return the sphere test alone in PhysicsWorld._update_islands and the first
    assertion fails; ENTER back at 0.4 fails the 0.7 m case.)"""
    prof = default_profile(skeleton)
    rot = np.tile([1.0, 0.0, 0.0, 0.0], (skeleton.num_joints, 1))
    hips = float(skeleton.offsets[0][1])
    assert 2 * reach(skeleton, prof, skeleton.offsets) + ENTER > 1.6  # the spheres alone would pull it in
    for gap, joins in ((1.6, False), (0.7, False), (0.5, True)):
        pw = PhysicsWorld()
        pw.add_ragdoll(1, skeleton, prof, [0.0, hips, 0.0], rot)
        pw.add_ragdoll(2, skeleton, prof, [gap, hips, 0.0], rot)
        pw.drive(1, [0.0, hips, 0.0], rot, 0.0, 0.0)
        pw.drive_animated([2], [[gap, hips, 0.0]], [rot])
        pw.step()
        assert pw.in_model(1) and pw.in_model(2) is joins
