"""``update_locomotion_batch``: a crowd in Locomotion stepped over arrays, what each puppet is set to.

A crowd's free puppets take the array path; a puppet running the legacy controller must still get the
legacy follower, which walks without the leg IK's foot locks, and every free puppet stands tall, ends
a put-down's "leave it there" and is grounded, exactly as ``update_locomotion`` does one by one.
Written for the seventh mutation round (docs/mutation.md): seen failing on the legacy column read as
never legacy (``tuning_columns``' ``"legacy"`` misspelt), and on the batch's IK set-up mutated.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from engine.blend.locomotion import LocomotionPlayer
from engine.ecs import World
from engine.hashing import state_hash
from engine.ik.system import IKRequest
from engine.statemachine import Brain, step_machine
from engine.statemachine.puppet import Handling, PuppetBody
from engine.statemachine.puppet import plugin as puppet_plugin
from engine.statemachine.puppet.senses import sense
from input.hub import InputHub
from puppetphone.games import make_app


def _one_by_one(world: World) -> None:
    for e, body, brain in world.query(PuppetBody, Brain):
        sense(world, e, body)
        step_machine(world, e, brain)


def _crowd(seed: int):  # type: ignore[no-untyped-def]
    app = make_app("sandbox", seed, InputHub([]), {"puppets": 6})
    app.run_steps(3)
    rows = app.world.query(PuppetBody, Handling, IKRequest)
    e0, body, _, _ = rows[1]
    body.tuning = replace(body.tuning, controller="legacy")
    rows[2][2].left = int(e0)  # a put-down's "leave it there"
    ik = rows[3][3]
    ik.grounding, ik.sphere_centre, ik.sphere_radius = False, np.array([0.0, 1.0, 0.0]), 0.3
    rows[4][1].walk_velocity = np.array([0.8, 0.0, -0.5])
    return app


def _unlink(world: World) -> None:
    """An ``np.float64`` heading no row block holds exactly: the batch stays plain objects (``engine.rows``)."""
    body = world.query(PuppetBody)[5][1]
    body.heading = np.float64(body.heading)  # what the row block cannot hold


@pytest.mark.parametrize("linked", [True, False])
def test_a_legacy_puppet_in_a_crowd_walks_without_foot_locks_as_one_by_one(
    linked: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Linked to a row block (who is legacy read from its tuning column) or plain objects (read body by body)."""
    batched = _crowd(21)
    monkeypatch.setattr(puppet_plugin, "brain_system", _one_by_one)
    single = _crowd(21)
    for step in range(4):
        if not linked:
            _unlink(batched.world)
            _unlink(single.world)
        batched.step()
        single.step()
        assert state_hash(batched.world) == state_hash(single.world), f"differs at step {step}"
    rows = batched.world.query(PuppetBody, Handling, IKRequest)
    assert [r[3].foot_lock.enabled for r in rows] == [True, False, True, True, True, True]
    assert all(r[2].left is None for r in rows)
    assert all(r[3].grounding and r[3].sphere_centre is None and r[3].sphere_radius == 0.0 for r in rows)


def _free_world(legacy_at: int = -1) -> tuple[World, list[int]]:
    """Puppets no stick holds, spawned bare (no app): some still walking, each with its own heading."""
    from engine.components import Transform

    world = World()
    made = []
    for i in range(4):
        body = PuppetBody(held_by=None, heading=0.4 * i, walk_velocity=np.array([0.3 * i, 0.0, 1.0 - 0.2 * i]))
        if i == legacy_at:
            body.tuning = replace(body.tuning, controller="legacy")
        ik = IKRequest()
        ik.grounding, ik.sphere_centre, ik.sphere_radius = False, np.array([0.0, 1.0, 0.0]), 0.3
        handling = Handling()
        handling.left = 99
        player = LocomotionPlayer()
        player.height = 0.6
        brain = Brain(machine=None)  # type: ignore[arg-type]  # update_locomotion does not read it
        made.append(world.spawn(Transform(position=np.array([float(i), 0.9, 0.0])), body, player, ik, brain, handling))
    return world, made


def _state(world: World, made: list[int]) -> list[tuple[object, ...]]:
    from engine.components import Transform

    out: list[tuple[object, ...]] = []
    for e in made:
        b, p, ik, h = (
            world.get(e, PuppetBody),
            world.get(e, LocomotionPlayer),
            world.get(e, IKRequest),
            world.get(e, Handling),
        )
        out.append(
            (b.heading, b.walk_velocity.tolist(), b.walk_rate.tolist(), p.speed, p.height, h.left, ik.grounding)
            + (ik.sphere_centre, ik.sphere_radius, ik.foot_lock.enabled, world.get(e, Transform).rotation.tolist())
        )
    return out


@pytest.mark.parametrize("legacy_at", [-1, 2])
def test_columns_without_component_lists_are_looked_up_entity_by_entity(legacy_at: int) -> None:
    """``PuppetColumns`` with only entities and bodies (no transforms, players, handling or IK lists, no row
    block): the batch looks each component up and gives what ``update_locomotion`` gives one by one."""
    from engine.statemachine.puppet.ground_states import update_locomotion, update_locomotion_batch
    from engine.statemachine.puppet.spec import PuppetColumns

    world, made = _free_world(legacy_at)
    update_locomotion_batch(
        world,
        PuppetColumns(made, [world.get(e, PuppetBody) for e in made], np.zeros(len(made), dtype=bool)),
        np.arange(len(made)),
    )
    alone, alone_made = _free_world(legacy_at)
    for e in alone_made:
        update_locomotion(alone, e, alone.get(e, Brain))
    assert _state(world, made) == _state(alone, alone_made)
    assert world.get(made[1], LocomotionPlayer).speed > 0.0  # they do walk


def test_a_standing_crowds_ik_requests_are_set_again_only_after_someone_assigned_them() -> None:
    """The IK set-up of the batch is skipped while no request field was assigned since it ran
    (``_stand_requests``): a change behind the assignment log stays, one assigned is undone at the
    next step. Broken once by dropping the skip (the first assertion fails) and once by dropping the
    assignment marks' check (the second fails)."""
    app = make_app("sandbox", 3, InputHub([]), {"puppets": 6})
    app.run_steps(3)
    ik = app.world.query(IKRequest)[2][1]
    ik.foot_lock.__dict__["enabled"] = False  # behind the log: nobody does this, so the skip cannot see it
    app.step()
    assert ik.foot_lock.enabled is False
    ik.sphere_radius = 0.4  # another system asks for something: the next step grounds it again
    app.step()
    assert ik.foot_lock.enabled is True and ik.sphere_radius == 0.0 and ik.grounding is True
