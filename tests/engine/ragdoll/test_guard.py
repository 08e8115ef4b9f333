"""Physics that no input can break: bounded speeds, undone failures, NaN refused, ghosts apart."""

from __future__ import annotations

from collections.abc import Callable

import mujoco
import numpy as np
import pytest

import engine.ragdoll._guard as guard
from engine import quat
from engine.app import App
from engine.components import LocalPose, Puppet, Transform
from engine.ragdoll import PhysicsWorld, Ragdoll, RagdollMode, default_profile, spawn_snowball
from engine.ragdoll._guard import MAX_LINEAR, PhysicsRecovery
from engine.ragdoll.components import Prop
from engine.skeleton import Skeleton


def test_speeds_are_bounded_before_mujoco_sees_them(make_app: Callable[..., tuple[App, int]]) -> None:
    app, _ = make_app(mode=RagdollMode.LIMP)
    ball = spawn_snowball(app.world, [5.0, 0.15, 0.0], 0.15, velocity=[1e4, 0.0, 0.0])
    app.step()
    assert np.linalg.norm(app.world.get(ball, Prop).velocity[:3]) <= MAX_LINEAR * np.sqrt(3)
    assert app.world.get(ball, Transform).position[0] < 5.0 + MAX_LINEAR * app.world.dt + 1e-9


def test_a_step_mujoco_cannot_take_is_undone_and_counted(
    make_app: Callable[..., tuple[App, int]], monkeypatch: pytest.MonkeyPatch
) -> None:
    app, e = make_app(mode=RagdollMode.LIMP)
    app.run_steps(3)
    pw = app.world.resource(PhysicsWorld)
    before = pw.data.qpos.copy()

    def fail(m: mujoco.MjModel, d: mujoco.MjData) -> None:
        raise mujoco.FatalError("mj_stackAlloc: out of memory")

    monkeypatch.setattr(guard.mujoco, "mj_step", fail)
    with pytest.warns(PhysicsRecovery, match="out of memory"):
        app.step()
    assert pw.recoveries == 1
    np.testing.assert_array_equal(pw.data.qpos, before)  # the last good state
    assert not pw.data.qvel.any()  # the offending bodies at rest
    monkeypatch.undo()
    app.run_steps(5)  # and the game goes on
    assert pw.recoveries == 1 and np.isfinite(pw.data.qpos).all()


def test_a_mujoco_warning_is_caught_not_printed(
    make_app: Callable[..., tuple[App, int]], capfd: pytest.CaptureFixture[str]
) -> None:
    app, e = make_app(mode=RagdollMode.LIMP)
    app.step()
    pw = app.world.resource(PhysicsWorld)
    pw.data.qvel[3] = np.nan  # what a broken integrator would leave behind
    with pytest.warns(PhysicsRecovery):
        app.step()
    assert pw.recoveries == 1
    assert np.isfinite(pw.data.qpos).all() and np.isfinite(pw.data.qvel).all()
    assert "WARNING" not in capfd.readouterr().out


def test_a_nan_target_never_reaches_mujoco(make_app: Callable[..., tuple[App, int]]) -> None:
    for mode in (RagdollMode.ANIMATED, RagdollMode.ACTIVE):
        app, e = make_app(mode=mode)
        app.run_steps(2)
        pw = app.world.resource(PhysicsWorld)

        def poison(world, e=e) -> None:  # type: ignore[no-untyped-def]
            world.get(e, LocalPose).rotations[3] = np.nan

        app.add_system("ik", poison)
        app.run_steps(3)
        assert pw.recoveries == 3
        assert np.isfinite(app.world.get(e, LocalPose).rotations).all()
        assert pw.data is None or np.isfinite(pw.data.qpos).all()


def test_two_puppets_on_one_spot_separate_without_exploding(
    make_app: Callable[..., tuple[App, int]], skeleton: Skeleton
) -> None:
    app, a = make_app(mode=RagdollMode.LIMP)
    rd = Ragdoll(default_profile(skeleton))
    rd.set_mode(RagdollMode.LIMP, immediate=True)
    b = app.world.spawn(Puppet(skeleton), LocalPose(np.array([0.02, 1.96, 0.0]), quat.identity(17)), rd)
    pw = app.world.resource(PhysicsWorld)
    speeds = []
    for _ in range(90):
        app.step()
        speeds.append(max(np.linalg.norm(pw.root_velocity(k)[:3]) for k in (a, b)))
    assert max(speeds) < 8.0  # a fall from 2 m, not a launch
    assert pw.recoveries == 0 and pw.data.ncon < 100
