"""The landing crouch is as deep as the landing was fast (thesis §6.3: land, absorb, go on)."""

from __future__ import annotations

import numpy as np

from engine.blend.locomotion import LocomotionPlayer
from engine.statemachine import Brain
from engine.statemachine.puppet.body import Jumping, Landing, PuppetBody
from engine.statemachine.puppet.jump_state import enter_land, update_land
from input.hub import InputHub
from puppetphone.games import make_app


def _lowest_hips(fall_speed: float) -> float:
    app = make_app("sandbox", 0, InputHub([]), {"scene": "empty", "puppets": 1})
    world = app.world
    entity, brain = next(iter(world.query(Brain)))
    body = world.get(entity, PuppetBody)
    world.get(entity, Jumping).air_velocity = np.array([0.0, -fall_speed, 0.0])
    enter_land(world, entity, brain)
    lowest = np.inf
    player = world.get(entity, LocomotionPlayer)
    while world.get(entity, Landing).timer < body.tuning.landing:
        update_land(world, entity, brain)
        lowest = min(lowest, float(player.height))
    return lowest


def test_a_hop_barely_dips_and_a_high_fall_crouches_low():
    hop, high = _lowest_hips(1.0), _lowest_hips(5.0)
    assert hop > high + 0.15  # metres of hips height between the two crouches
    assert high < 0.7 and hop > 0.85
