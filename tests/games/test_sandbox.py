"""The sandbox crowd: wanderers walk, only the first puppet is grabbable, and it replays."""

from __future__ import annotations

import numpy as np
import pytest

from engine.app import App
from engine.components import Grabbable, Transform
from engine.statemachine.puppet import PuppetBody
from games.base import GameOptionError
from games.sandbox import GAME
from games.wander import Wanderer
from input.hub import InputHub
from puppetphone.games import make_app


def _crowd(n: int, steps: int, seed: int = 3) -> App:
    app = make_app("sandbox", seed, InputHub(), GAME.prepare({**GAME.options, "puppets": str(n)}))
    app.run_steps(steps)
    return app


def test_one_puppet_by_default() -> None:
    app = make_app("sandbox", 0, InputHub())
    assert len(app.world.query(PuppetBody)) == 1
    assert not app.world.query(Wanderer)


def test_wanderers_walk_at_their_own_paces_and_only_the_first_is_grabbable() -> None:
    app = _crowd(6, 1)
    start = {e: tr.position.copy() for e, _, tr in app.world.query(Wanderer, Transform)}
    app.run_steps(120)
    w = app.world
    assert len(w.query(PuppetBody)) == 6 and len(w.query(Grabbable)) == 1
    moved = [np.linalg.norm(tr.position - start[e]) for e, _, tr in w.query(Wanderer, Transform)]
    assert min(moved) > 0.5
    assert len({round(wd.speed, 3) for _, wd in w.query(Wanderer)}) == 5


def test_a_crowd_is_deterministic() -> None:
    a, b = _crowd(4, 90), _crowd(4, 90)
    pa = [tr.position for _, _, tr in a.world.query(Wanderer, Transform)]
    pb = [tr.position for _, _, tr in b.world.query(Wanderer, Transform)]
    np.testing.assert_array_equal(pa, pb)


def test_the_crowd_size_is_a_checked_option() -> None:
    assert GAME.prepare({**GAME.options, "puppets": "3"}) == {"scene": "empty", "puppets": 3}
    for bad in ("0", "-2", "1001", "many"):
        with pytest.raises(GameOptionError, match="puppets must be"):
            GAME.prepare({**GAME.options, "puppets": bad})


def test_a_wanderer_whose_ragdoll_leaves_the_animation_is_no_longer_steered_at_the_next_step() -> None:
    """Who is animated is kept between steps while no ragdoll mode is assigned (``wander._animated``); a
    ``set_mode`` must reach the next step's steering. Broken once by keeping it without the assignment mark:
    the limp wanderer's heading was still turned toward its goal."""
    from engine.ragdoll.components import Ragdoll, RagdollMode

    app = _crowd(4, 5)
    e, wanderer, body, rd = app.world.query(Wanderer, PuppetBody, Ragdoll)[0]
    wanderer.goal = np.array([50.0, 0.0, 0.0])  # far to the side: steering turns the heading
    app.step()
    turned = body.heading
    app.step()
    assert body.heading != turned  # still steered
    rd.set_mode(RagdollMode.LIMP, immediate=True)
    app.step()
    kept = body.heading
    app.step()
    assert body.heading == kept
