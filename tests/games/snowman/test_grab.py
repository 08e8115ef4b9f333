"""Grabbing a snowman (or the puppet) by its body with the mouse holds it at the height it stands.

The mouse's stick slides in the plane of the held point; a press above the anchor (the
snowman's hips are its bottom ball's centre, so a press on its middle ball) was taken along
the ray and held it lower than it stood: under the crouch threshold, it crouched and started
rolling a ball at once; a big snowman held above its hips was lifted off its feet and fell.
"""

from __future__ import annotations

import numpy as np
import pygame
import pytest

from engine.components import Transform
from engine.statemachine import Brain
from engine.statemachine.puppet.body import PuppetBody
from games.snowman.alive import bring_to_life
from games.snowman.game import camera
from games.snowman.rig import SnowmanShape
from input.hub import InputHub
from input.mouse import MouseSource
from input.mousebot import MouseBot
from puppetphone.games import make_app


@pytest.mark.parametrize("shape", [SnowmanShape(0.45, 0.32, 0.22), SnowmanShape(0.7, 0.45, 0.27)])
def test_a_snowman_grabbed_anywhere_on_its_body_stands_as_it_stood(shape: SnowmanShape) -> None:
    mouse = MouseSource()
    app = make_app("snowman", 0, InputHub([mouse]))
    snowman = bring_to_life(app.world, shape, np.array([1.5, 0.0, 1.5]), 0.0, 1)
    app.step()
    bot = MouseBot(app, mouse, camera())
    body, tr = app.world.get(snowman, PuppetBody), app.world.get(snowman, Transform)
    grabbed = 0
    for height in np.arange(0.3, 1.2, 0.1):
        bot.move_to_pixel(bot.pixel(tr.position + np.array([0.0, height, 0.0])), (0, 0, 0))
        bot.step()
        bot._send(pygame.MOUSEBUTTONDOWN, pos=bot.pos, button=1)
        bot.step()
        if body.held_by is None:
            continue  # above the pick sphere: nothing grabbed
        grabbed += 1
        bot.wait(0.7)
        assert body.target_height == pytest.approx(body.tuning.stand_height, abs=0.01), height
        assert app.world.get(snowman, Brain).active == "Locomotion", height
        bot.release()
        bot.wait(1.0)
    assert grabbed >= 3


def test_a_ball_carried_low_through_a_big_one_rides_over_it_and_leaves_it_where_it_was() -> None:
    """It plowed the big ball 5 m aside (27 m two notches up); now it passes over, and let go there it stacks."""
    from engine.ragdoll.components import Prop
    from games.snowman.components import Stacked
    from games.snowman.rules import spawn_ball

    mouse = MouseSource()
    app = make_app("snowman", 0, InputHub([mouse]))
    big = spawn_ball(app.world, np.array([1.4, 0.45, 0.9]), 0.45)
    small = spawn_ball(app.world, np.array([-1.3, 0.22, 1.3]), 0.22)
    app.step()
    bot = MouseBot(app, mouse, camera())
    bot.press_on(small)
    before = app.world.get(big, Transform).position.copy()
    heights = []
    bot.on_step.append(lambda a: heights.append(float(a.world.get(small, Transform).position[1])))
    bot.drag_path([np.array([1.4, 0.0, 0.9])], 1.2)  # straight at the big ball, not lifted
    bot.wait(0.5)
    top = before[1] + app.world.get(big, Prop).radius
    assert max(heights) > top, "the carried ball did not ride over"
    assert np.linalg.norm((app.world.get(big, Transform).position - before)[[0, 2]]) < 0.02, "the big ball was shoved"
    bot.release()
    bot.wait(1.5)
    assert app.world.has(small, Stacked) or not app.world.alive(small)  # on top (or already part of a snowman)
