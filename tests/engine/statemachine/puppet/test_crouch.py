"""Crouch hysteresis, asserted through the state machine (``step_machine``), not a golden hash.

Held by the stick, the puppet crouches once the stick takes its hips below ``crouch_enter`` and
stands again only above ``crouch_exit``, a band higher: a stick hovering between the two keeps
whatever the puppet is doing, so a shaky hand at the threshold does not flicker Crouch on and off.

Shown to fail when broken: ``wants_stand`` comparing with ``crouch_enter`` (no band: Crouch ends
inside it), ``wants_crouch`` comparing with ``crouch_exit`` (crouches inside the band), the tuning's
``crouch_exit`` set equal to ``crouch_enter``, or a released puppet left crouching.
"""

from __future__ import annotations

import numpy as np
import pytest

from engine.components import Stick, Transform
from engine.statemachine import Brain, step_machine
from engine.statemachine.puppet.body import PuppetBody
from input.hub import InputHub
from puppetphone.games import make_app


@pytest.fixture
def puppet():  # type: ignore[no-untyped-def]
    """The sandbox puppet standing after half a second, and a function holding it at a hips height."""
    app = make_app("sandbox", 5, InputHub())
    app.run_steps(30)
    world = app.world
    entity, brain = next(iter(world.query(Brain)))
    body = world.get(entity, PuppetBody)
    stick = world.query(Stick)[0][0]
    where = np.array(world.get(entity, Transform).position)

    def hold(height: float | None, steps: int = 3) -> list[str]:
        """Step the machine ``steps`` times with the stick holding the hips at ``height`` (None: released)."""
        seen = []
        for _ in range(steps):
            body.held_by = None if height is None else stick
            body.target = np.array([where[0], 0.0, where[2]])
            if height is not None:  # released: the last height stays, as ``sense`` leaves it
                body.target_height = height
            step_machine(world, entity, brain)
            seen.append(brain.active)
        return seen

    assert brain.active == "Locomotion"
    return body.tuning, hold


def test_the_band_between_entering_and_leaving_a_crouch(puppet) -> None:  # type: ignore[no-untyped-def]
    t, hold = puppet
    assert t.crouch_exit - t.crouch_enter >= 0.03  # a band a shaky hand does not cross by accident
    inside = [t.crouch_enter + f * (t.crouch_exit - t.crouch_enter) for f in (0.2, 0.5, 0.8)]
    below, above = t.crouch_enter - 0.02, t.crouch_exit + 0.02
    # Standing, the stick lowered into the band: still standing.
    for h in inside:
        assert hold(h) == ["Locomotion"] * 3, h
    # Below the band: it crouches at once.
    assert hold(below)[0] == "Crouch"
    # Back up into the band, anywhere in it: still crouching.
    for h in reversed(inside):
        assert hold(h) == ["Crouch"] * 3, h
    # Above the band: it stands at once ...
    assert hold(above)[0] == "Locomotion"
    # ... and going back into the band does not crouch it again.
    for h in inside:
        assert hold(h) == ["Locomotion"] * 3, h


def test_the_thresholds_themselves_are_inside_the_band(puppet) -> None:  # type: ignore[no-untyped-def]
    """*Below* ``crouch_enter`` crouches, *above* ``crouch_exit`` stands: at either threshold exactly nothing
    changes. Found by the mutation run (``<`` made ``<=``, ``>`` made ``>=`` survived)."""
    t, hold = puppet
    assert hold(t.crouch_enter) == ["Locomotion"] * 3
    assert hold(t.crouch_exit) == ["Locomotion"] * 3
    assert hold(t.crouch_enter - 1e-9)[0] == "Crouch"
    assert hold(t.crouch_enter) == ["Crouch"] * 3
    assert hold(t.crouch_exit) == ["Crouch"] * 3
    assert hold(t.crouch_exit + 1e-9)[0] == "Locomotion"


def test_a_released_puppet_stands_up_from_a_crouch(puppet) -> None:  # type: ignore[no-untyped-def]
    t, hold = puppet
    assert hold(t.crouch_height)[-1] == "Crouch"
    assert hold(None)[0] == "Locomotion"
