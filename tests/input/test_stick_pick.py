"""What the stick points at: a puppet is picked by any part of the body it is drawn with.

Its grab sphere sits at the hips (radius 0.45 × hip height), so a press on its feet or its head
found nothing although the cursor was on the puppet. Broken once by returning only the sphere
hit from ``stick_target`` (the bone capsules ignored): the feet, toes and head presses below
grab nothing and the first test fails.
"""

from __future__ import annotations

import numpy as np
import pygame
import pytest

from engine.components import Name, Puppet, Stick, WorldPose
from engine.ecs import Entity
from engine.fk import world_points
from engine.statemachine import Brain
from engine.statemachine.puppet.body import PuppetBody
from games.snowman.game import camera
from input.hub import InputHub
from input.mouse import MouseSource
from input.mousebot import MouseBot
from input.stick_geometry import pick_capsules
from puppetphone.games import make_app


def _ray(origin: list[float], towards: list[float]) -> tuple[np.ndarray, np.ndarray]:
    o = np.asarray(origin, dtype=np.float64)
    d = np.asarray(towards, dtype=np.float64) - o
    return o, d / np.linalg.norm(d)


def test_a_capsule_is_entered_where_the_eye_meets_it() -> None:
    a = np.array([[0.0, 0.0, 5.0], [0.0, 0.0, 3.0], [-1.0, 2.0, 8.0]])
    b = np.array([[0.0, 2.0, 5.0], [0.0, 0.0, 3.0], [1.0, 2.0, 8.0]])
    r = np.array([0.5, 0.2, 0.3])
    o, d = _ray([0.0, 1.0, 0.0], [0.0, 1.0, 1.0])
    assert pick_capsules(o, d, a, b, r) == (0, 4.5)  # square onto the side of the upright one
    o, d = _ray([0.0, 0.0, 0.0], [0.0, 0.0, 1.0])
    assert pick_capsules(o, d, a, b, r) == (1, pytest.approx(2.8))  # the ball in front hides the rest
    o, d = _ray([0.0, 3.0, 5.0], [0.0, 2.0, 5.0])
    assert pick_capsules(o, d, a, b, r) == (0, pytest.approx(0.5))  # straight down onto the top cap
    o, d = _ray([0.0, 2.0, 0.0], [0.0, 2.0, 1.0])
    assert pick_capsules(o, d, a, b, r) == (0, pytest.approx(4.5))  # along the top: the cap's side
    o, d = _ray([0.0, 1.0, 5.0], [1.0, 1.0, 5.0])
    assert pick_capsules(o, d, a, b, r) == (0, 0.0)  # starting inside
    o, d = _ray([0.0, 1.0, 0.0], [0.0, 1.0, -1.0])
    assert pick_capsules(o, d, a, b, r) is None  # all behind
    o, d = _ray([0.0, 1.0, 0.0], [0.0, 1.0, 1.0])
    assert pick_capsules(o, d, a, b, r, max_distance=4.0) is None  # out of reach
    o, d = _ray([0.0, 2.0, 0.0], [0.0, 2.0, 1.0])
    assert pick_capsules(o, d, a[2:], b[2:], r[2:]) == (0, pytest.approx(7.7))  # lying across the ray


def test_a_segment_along_the_ray_is_entered_at_its_near_end() -> None:
    a, b, r = np.array([[0.0, 0.0, 9.0]]), np.array([[0.0, 0.0, 4.0]]), np.array([0.5])
    o, d = _ray([0.0, 0.0, 0.0], [0.0, 0.0, 1.0])
    assert pick_capsules(o, d, a, b, r) == (0, pytest.approx(3.5))


def _puppet(app: object) -> Entity:
    world = app.world  # type: ignore[attr-defined]
    return next(e for e, name, _ in world.query(Name, Puppet) if name.value == "puppet")


def _press_at(bot: MouseBot, point: np.ndarray) -> Entity | None:
    bot.move_to_pixel(bot.pixel(point), (0, 0, 0))
    bot.step()
    bot._send(pygame.MOUSEBUTTONDOWN, pos=bot.pos, button=1)
    bot.step()
    return next(stick.grabbed for _, stick in bot.app.world.query(Stick))


def _body_points(app: object, puppet: Entity) -> dict[str, np.ndarray]:
    """Points on the drawn body outside the hips' grab sphere (which reaches from 0.52 m to 1.38 m)."""
    world = app.world  # type: ignore[attr-defined]
    skeleton = world.get(puppet, Puppet).skeleton
    pose = world.get(puppet, WorldPose)
    joint = {name: pose.positions[skeleton.index(name)] for name in ("l_foot", "r_foot", "head", "l_hand")}
    tips = world_points(skeleton, pose.positions, pose.rotations)
    toe = tips[skeleton.index("l_foot")]
    return {
        "l_foot": joint["l_foot"],
        "r_foot": joint["r_foot"],
        "toes": joint["l_foot"] + 0.8 * (toe - joint["l_foot"]),
        "head": joint["head"] + np.array([0.0, 0.08, 0.0]),
        "head_top": tips[skeleton.index("head")] - np.array([0.0, 0.03, 0.0]),
        "l_hand": joint["l_hand"],
    }


@pytest.mark.parametrize("part", ["l_foot", "r_foot", "toes", "head", "head_top", "l_hand"])
def test_a_press_on_any_part_of_the_puppet_grabs_it_and_holds_it_standing(part: str) -> None:
    mouse = MouseSource()
    app = make_app("snowman", 0, InputHub([mouse]))
    app.step()
    bot = MouseBot(app, mouse, camera())
    puppet = _puppet(app)
    assert _press_at(bot, _body_points(app, puppet)[part]) == puppet, part
    bot.wait(0.7)
    body = app.world.get(puppet, PuppetBody)
    assert app.world.get(puppet, Brain).active == "Locomotion"
    assert body.target_height == pytest.approx(body.tuning.stand_height, abs=0.02)


def test_a_press_on_the_snow_beside_the_feet_grabs_nothing() -> None:
    mouse = MouseSource()
    app = make_app("snowman", 0, InputHub([mouse]))
    app.step()
    bot = MouseBot(app, mouse, camera())
    points = _body_points(app, _puppet(app))
    outward = points["l_foot"] - points["r_foot"]
    outward[1] = 0.0
    beside = points["l_foot"] * [1.0, 0.0, 1.0] + 0.3 * outward / np.linalg.norm(outward)
    assert _press_at(bot, beside) is None
