"""The ground states' own rules, one call at a time: which follower runs (and with what), when the
puppet is lifted or yanked out of the ground states, the hips height each state asks for, and the
leg IK they set. ``test_crouch.py`` covers the crouch band through the machine; before these tests
the rest was watched only by the recorded sessions' golden hashes.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np
import pytest

from engine.blend.locomotion import LocomotionPlayer
from engine.components import Transform
from engine.ecs import World
from engine.ik.system import IKRequest
from engine.statemachine.machine import Brain
from engine.statemachine.puppet import ground_states
from engine.statemachine.puppet.body import Handling, PuppetBody, PuppetTuning
from engine.statemachine.puppet.ground_states import (
    follow_stick,
    lifted,
    locomotion_fits,
    update_crouch,
    update_locomotion,
)

T = PuppetTuning()
_AT = np.array([1.0, 0.9, 2.0])


def _puppet(
    tuning: PuppetTuning = T, held: bool = True, height: float = 0.95, ahead: np.ndarray | None = None
) -> tuple[World, int, PuppetBody, LocomotionPlayer, IKRequest, Brain]:
    world = World()
    body = PuppetBody(
        tuning=tuning,
        held_by=5 if held else None,
        target_height=height,
        target=_AT + (np.zeros(3) if ahead is None else ahead),
    )
    player, ik = LocomotionPlayer(), IKRequest()
    ik.grounding, ik.sphere_centre, ik.sphere_radius = False, np.array([0.0, 1.0, 0.0]), 0.3
    brain = Brain(machine=None)  # type: ignore[arg-type]
    entity = world.spawn(Transform(position=np.array(_AT)), body, player, ik, brain, Handling())
    return world, entity, body, player, ik, brain


@pytest.fixture
def followers(monkeypatch: pytest.MonkeyPatch) -> list[tuple[str, tuple[Any, ...]]]:
    """Record which follower ``follow_stick`` calls, and with what."""
    calls: list[tuple[str, tuple[Any, ...]]] = []
    monkeypatch.setattr(ground_states, "follow_velocity", lambda *a: calls.append(("spring", a)))
    monkeypatch.setattr(ground_states, "follow_stick_legacy", lambda *a: calls.append(("legacy", a)))
    return calls


def test_the_spring_controller_follows_with_the_foot_locks_on(followers: list) -> None:
    world, e, body, player, ik, _ = _puppet()
    ik.foot_lock.enabled = False
    follow_stick(world, e, body, player)
    follow_stick(world, e, body, player, speed_scale=0.5, lead_band=0.06)
    assert followers == [
        ("spring", (world, e, body, player, 1.0, 0.02)),
        ("spring", (world, e, body, player, 0.5, 0.06)),
    ]
    assert ik.foot_lock.enabled is True


def test_the_legacy_controller_follows_as_it_was_without_foot_locks(followers: list) -> None:
    world, e, body, player, ik, _ = _puppet(tuning=replace(T, controller="legacy"))
    follow_stick(world, e, body, player, speed_scale=0.5)
    assert followers == [("legacy", (world, e, body, player, 0.5))]
    assert ik.foot_lock.enabled is False


def test_lifted_means_held_clearly_above_standing_height() -> None:
    over = T.stand_height + T.lift_limit + 0.01
    assert lifted(PuppetBody(held_by=5, target_height=over))
    assert not lifted(PuppetBody(held_by=5, target_height=over - 0.02))
    assert not lifted(PuppetBody(held_by=None, target_height=over))


def test_a_released_puppet_always_fits_the_ground_states() -> None:
    world, e, _body, *_ = _puppet(held=False, ahead=np.array([50.0, 0.0, 0.0]), height=5.0)
    assert locomotion_fits(world, e, None)  # type: ignore[arg-type]


def test_a_puppet_yanked_past_its_reach_leaves_the_ground_states() -> None:
    """The reach is measured on the ground (a stick high above does not yank) and grows with the
    puppet's speed with the spring controller; the legacy one keeps the fixed drag limit."""
    world, e, body, *_ = _puppet(ahead=np.array([0.0, 0.0, T.drag_limit - 0.05]))
    assert locomotion_fits(world, e, None)  # type: ignore[arg-type]
    body.target = _AT + np.array([0.0, 0.0, T.drag_limit + 0.05])
    assert not locomotion_fits(world, e, None)  # type: ignore[arg-type]
    body.target = _AT + np.array([0.0, 0.4, T.drag_limit - 0.05])  # higher, not further
    assert locomotion_fits(world, e, None)  # type: ignore[arg-type]
    body.target = _AT + np.array([T.drag_limit + 0.3, 0.0, 0.0])
    body.walk_velocity = np.array([0.0, 0.0, 2.0])  # running: reach 1.6 + 0.5 * 2
    assert locomotion_fits(world, e, None)  # type: ignore[arg-type]
    body.tuning = replace(T, controller="legacy")
    assert not locomotion_fits(world, e, None)  # type: ignore[arg-type]


def test_a_lifted_puppet_leaves_the_ground_states_even_at_its_stick() -> None:
    world, e, *_ = _puppet(height=T.stand_height + T.lift_limit + 0.05)
    assert not locomotion_fits(world, e, None)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("held", "height", "asked"),
    [
        (False, 0.3, None),  # released: stand tall, whatever the stick's last height
        (True, T.crouch_exit, None),  # at the exit height: standing
        (True, T.crouch_exit - 0.01, T.crouch_exit - 0.01),  # a slight dip
        (True, T.crouch_enter - 0.2, T.crouch_enter),  # never lower than the crouch's entry in Locomotion
    ],
)
def test_locomotion_stands_tall_or_dips_with_the_stick(held: bool, height: float, asked: float | None) -> None:
    world, e, _body, player, ik, brain = _puppet(held=held, height=height)
    hand = world.get(e, Handling)
    hand.left = 42
    update_locomotion(world, e, brain)
    assert player.height == (None if asked is None else pytest.approx(asked))
    assert (hand.left == 42) == (asked is not None)  # standing up ends a put-down's "leave it"
    assert ik.grounding is True and ik.sphere_centre is None and ik.sphere_radius == 0.0


@pytest.mark.parametrize(("height", "asked"), [(0.1, T.crouch_height), (0.62, 0.62), (0.95, T.crouch_exit)])
def test_crouch_holds_the_hips_as_low_as_the_stick_within_the_crouch(height: float, asked: float) -> None:
    world, e, _body, player, ik, brain = _puppet(height=height)
    assert T.crouch_height < 0.62 < T.crouch_exit
    update_crouch(world, e, brain)
    assert player.height == pytest.approx(asked)
    assert ik.grounding is True and ik.sphere_centre is None and ik.sphere_radius == 0.0


def test_crouched_the_stick_must_lead_by_the_dead_band(followers: list) -> None:
    world, e, _body, _player, _ik, brain = _puppet(height=0.6)
    update_crouch(world, e, brain)
    update_locomotion(world, e, brain)
    assert [c[1][5] for c in followers] == [T.follow_deadband, 0.02]
