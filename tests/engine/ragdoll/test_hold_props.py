"""Held by the MotionStick (a spring on the chest, the rest dangles) and snowball props."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from engine.app import App
from engine.components import Transform
from engine.ragdoll import PhysicsWorld, Prop, Ragdoll, RagdollMode, install_physics, spawn_snowball


def test_held_chest_hangs_and_swings(make_app: Callable[..., tuple[App, int]], skeleton) -> None:  # type: ignore[no-untyped-def]
    app, e = make_app(np.array([0.0, 1.6, 0.0]))
    rd = app.world.get(e, Ragdoll)
    pw = app.world.resource(PhysicsWorld)
    chest, foot = skeleton.index("chest"), skeleton.index("l_foot")
    target = np.array([0.0, 2.2, 0.0])
    rd.grab("chest", target)
    for _ in range(180):
        app.step()
    pos = pw.body_positions(e)
    site = pw.data.site(pw.mujoco_name(e, "chest_hold")).xpos
    assert np.linalg.norm(site - target) < 0.1  # held by the spring, sagging a little under the weight
    assert pos[foot, 1] < pos[chest, 1] - 0.8  # the rest dangles below
    # move the hand sideways: the legs lag behind, then swing
    rd.grab("chest", target + [0.8, 0.0, 0.0])
    xs = []
    for _ in range(90):
        app.step()
        xs.append(pw.body_positions(e)[foot, 0])
    xs_arr = np.array(xs)
    assert xs_arr[5] < 0.4  # lagging behind the chest
    assert xs_arr.max() > 0.8  # swung past the hand's new position
    rd.release()
    app.step()
    assert not pw.data.eq_active[pw.model.eq(pw.mujoco_name(e, "chest_hold")).id]
    with pytest.raises(KeyError, match="holdable"):
        rd.grab("l_foot", target)


def test_snowball_rolls_on_the_ground() -> None:
    app = App(plugins=[install_physics])
    b = spawn_snowball(app.world, [0.0, 0.3, 0.0], radius=0.3, velocity=[2.0, 0.0, 0.0])
    for _ in range(60):
        app.step()
    tr, prop = app.world.get(b, Transform), app.world.get(b, Prop)
    v, w = prop.velocity[:3], prop.velocity[3:]
    assert tr.position[1] == pytest.approx(0.3, abs=0.01)
    assert 0.5 < v[0] < 2.0  # still rolling, slowed by friction
    assert w[2] == pytest.approx(-v[0] / 0.3, rel=0.05)  # rolling, not sliding
    assert not np.allclose(tr.rotation, [1, 0, 0, 0])


def test_snowballs_never_interpenetrate() -> None:
    app = App(plugins=[install_physics])
    a = spawn_snowball(app.world, [0.0, 0.25, 0.0], radius=0.25, velocity=[3.0, 0.0, 0.0])
    b = spawn_snowball(app.world, [1.5, 0.4, 0.0], radius=0.4)
    gaps = []
    for _ in range(90):
        app.step()
        pa, pb = app.world.get(a, Transform).position, app.world.get(b, Transform).position
        gaps.append(np.linalg.norm(pa - pb) - 0.65)
    assert min(gaps) > -0.01
    assert app.world.get(b, Transform).position[0] > 1.6  # the small one pushed the big one


def test_puppet_pushes_a_snowball(make_app: Callable[..., tuple[App, int]], skeleton) -> None:  # type: ignore[no-untyped-def]
    app, e = make_app(np.array([0.0, 0.95, -0.5]), mode=RagdollMode.ANIMATED)
    ball = spawn_snowball(app.world, [0.0, 0.2, 0.0], radius=0.2)
    from engine.components import LocalPose

    def walk_into(world):  # type: ignore[no-untyped-def]
        world.get(e, LocalPose).root = np.array([0.0, 0.95, -0.5 + 0.8 * world.time])

    app.add_system("animation", walk_into)
    for _ in range(90):
        app.step()
    x = app.world.get(ball, Transform).position
    assert x[2] > 0.5  # pushed along +Z ahead of the puppet
    assert x[1] == pytest.approx(0.2, abs=0.02)


def test_snowball_grows_at_run_time() -> None:
    app = App(plugins=[install_physics])
    b = spawn_snowball(app.world, [0.0, 0.1, 0.0], radius=0.1)
    pw = app.world.resource(PhysicsWorld)
    app.step()
    rebuilds = pw.rebuilds
    m0 = pw.model.body_mass[pw.model.body("pr1").id]
    prop = app.world.get(b, Prop)
    for i in range(30):
        prop.radius = 0.1 + 0.01 * (i + 1)
        app.step()
    assert pw.rebuilds == rebuilds  # resized in place
    gid = pw.model.geom("pr1").id
    assert pw.model.geom_size[gid, 0] == pytest.approx(0.4)
    assert pw.model.body_mass[pw.model.body("pr1").id] == pytest.approx(m0 * 64)
    for _ in range(30):
        app.step()
    assert app.world.get(b, Transform).position[1] == pytest.approx(0.4, abs=0.01)
    with pytest.raises(ValueError, match="positive"):
        pw.set_prop_radius(b, -1.0, 1.0)
    assert pw.model.geom_size[gid, 0] == pytest.approx(0.4)


def test_removing_a_prop_rebuilds_without_it() -> None:
    app = App(plugins=[install_physics])
    a = spawn_snowball(app.world, [0.0, 0.2, 0.0], radius=0.2)
    b = spawn_snowball(app.world, [1.0, 0.2, 0.0], radius=0.2, velocity=[0.0, 0.0, 1.0])
    for _ in range(10):
        app.step()
    pw = app.world.resource(PhysicsWorld)
    before = pw.prop_state(b)
    app.world.despawn(a)
    app.step()
    assert pw.prop_keys == [b]
    assert np.linalg.norm(pw.prop_state(b)[0] - before[0]) < 0.05
