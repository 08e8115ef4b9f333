"""Active ragdolls track the animation; modes ramp smoothly; the animated mode is exact."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from engine import quat
from engine.app import App
from engine.clip import Clip
from engine.components import LocalPose
from engine.ecs import World
from engine.pose import Pose
from engine.ragdoll import PhysicsWorld, Ragdoll, RagdollMode, blend_poses

# Stated tracking accuracy of an active ragdoll (muscle 1, pin 1) on a walk cycle.
MEAN_ERROR_DEG = 2.5
P95_ERROR_DEG = 7.0
MAX_ERROR_DEG = 14.0


def _animate(app: App, e: int, clip: Clip, speed: float = 1.2) -> None:
    def animate(world: World) -> None:
        p = clip.sample(world.time)
        lp = world.get(e, LocalPose)
        lp.root = p.root + np.array([0.0, 0.0, speed * world.time])
        lp.rotations = p.rotations

    app.add_system("animation", animate)


def test_active_mode_tracks_a_walk(make_app: Callable[..., tuple[App, int]], walk_clip: Clip) -> None:
    start = walk_clip.sample(0.0)
    lift = np.array([0.0, 0.3, 0.0])  # the walk is held just off the ground: we test the muscles
    clip = Clip(
        walk_clip.name, walk_clip.skeleton, walk_clip.fps, walk_clip.root + lift, walk_clip.rotations, loop=True
    )
    app, e = make_app(start.root + lift, start.rotations, mode=RagdollMode.ACTIVE)
    _animate(app, e, clip)
    pw = app.world.resource(PhysicsWorld)
    errors, root_err = [], []
    for i in range(180):
        app.step()
        target = clip.sample(app.world.time - app.world.dt)
        sim = pw.pose(e)
        if i >= 60:
            errors.append(np.degrees(quat.angle_between(sim.rotations, target.rotations)))
            root_err.append(np.linalg.norm(sim.root - target.root - [0, 0, 1.2 * (app.world.time - app.world.dt)]))
    err = np.array(errors)
    print("walk tracking error (deg): mean", err.mean(), "p95", np.percentile(err, 95), "max", err.max(axis=0).round(1))
    assert err.mean() < MEAN_ERROR_DEG, err.mean()
    assert np.percentile(err, 95) < P95_ERROR_DEG
    assert err.max() < MAX_ERROR_DEG, err.max(axis=0)
    assert max(root_err) < 0.03
    # blend weight 1: the pose written back is the simulation's
    np.testing.assert_allclose(app.world.get(e, LocalPose).rotations, pw.pose(e).rotations, atol=1e-12)


@pytest.mark.parametrize("simulated", [False, True])
def test_animated_mode_passes_the_pose_through(
    make_app: Callable[..., tuple[App, int]], walk_clip: Clip, simulated: bool
) -> None:
    start = walk_clip.sample(0.0)
    app, e = make_app(start.root, start.rotations, mode=RagdollMode.ANIMATED)
    _animate(app, e, walk_clip)
    pw = app.world.resource(PhysicsWorld)
    pw.simulate_animated = simulated  # alone it is left out of the model, unless asked
    drift = []
    for _ in range(30):
        app.step()
        t = app.world.time - app.world.dt
        target = walk_clip.sample(t)
        lp = app.world.get(e, LocalPose)
        np.testing.assert_allclose(lp.rotations, target.rotations, atol=1e-12)
        assert pw.in_model(e) is simulated
        if not simulated:  # not simulated: the body is exactly on its animation
            np.testing.assert_allclose(pw.pose(e).rotations, lp.rotations, atol=1e-12)
            assert pw.kinetic_energy(e) == 0.0
            continue
        # placed on the pose with its velocity, the bodies arrive where the animation goes next
        ahead = walk_clip.sample(app.world.time)
        drift.append(np.degrees(np.max(quat.angle_between(pw.pose(e).rotations, ahead.rotations))))
    assert not simulated or max(drift[1:]) < 5.0, drift  # the first step has no velocity yet


def test_going_limp_ramps_the_weights(make_app: Callable[..., tuple[App, int]]) -> None:
    app, e = make_app(mode=RagdollMode.ACTIVE)
    rd = app.world.get(e, Ragdoll)
    rd.set_mode(RagdollMode.LIMP)
    muscles = []
    for _ in range(30):
        app.step()
        muscles.append(rd.muscle_weight)
    steps = np.abs(np.diff([1.0, *muscles]))
    assert muscles[-1] == 0.0 and rd.pin_weight == 0.0
    assert steps.max() <= app.world.dt / rd.transition_time + 1e-12
    assert np.count_nonzero(steps) >= 10  # took about transition_time, not one frame


def test_mode_weights_are_validated() -> None:
    from engine.humanoid import humanoid_skeleton
    from engine.ragdoll import default_profile

    rd = Ragdoll(default_profile(humanoid_skeleton()))
    with pytest.raises(ValueError, match="0..1"):
        rd.set_mode(RagdollMode.ACTIVE, muscle=1.5)
    assert rd.mode is RagdollMode.ANIMATED


def test_blend_poses_endpoints_and_midpoint() -> None:
    a = Pose(np.zeros(3), quat.identity(3))
    b = Pose(np.array([1.0, 2.0, 0.0]), quat.from_axis_angle(np.tile([0.0, 1.0, 0.0], (3, 1)), np.full(3, 1.0)))
    np.testing.assert_array_equal(blend_poses(a, b, 0.0).rotations, a.rotations)
    np.testing.assert_array_equal(blend_poses(a, b, 1.0).root, b.root)
    mid = blend_poses(a, b, 0.5)
    np.testing.assert_allclose(mid.root, [0.5, 1.0, 0.0])
    np.testing.assert_allclose(quat.angle_between(mid.rotations, a.rotations), 0.5)
    per_joint = blend_poses(a, b, np.array([0.0, 1.0, 0.5]))
    np.testing.assert_allclose(quat.angle_between(per_joint.rotations, a.rotations), [0.0, 1.0, 0.5])
    with pytest.raises(ValueError, match="shape"):
        blend_poses(a, Pose(np.zeros(3), quat.identity(4)), 0.5)
