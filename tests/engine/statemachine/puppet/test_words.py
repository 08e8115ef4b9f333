"""A crowd's words at once (:func:`describe_puppets`) are each puppet's words (:func:`describe_puppet`).

Broken once to see it fail: with ``>`` for ``>=`` in the array form's running test, the
puppet moving at exactly the running speed read "walking" there and "running" one by one.
"""

import numpy as np

from engine.rows import row_store
from engine.statemachine import Brain
from engine.statemachine.puppet.body import PuppetBody
from engine.statemachine.puppet.words import RUN_FRACTION, describe_puppet, describe_puppets
from input.hub import InputHub
from puppetphone.games import make_app


def test_a_crowds_words_from_its_arrays_are_each_puppets_words_at_every_edge() -> None:
    app = make_app("sandbox", 0, InputHub(), {"puppets": 40})
    app.run_steps(30)
    world = app.world
    rows = world.query(Brain, PuppetBody)
    entities = [e for e, _, _ in rows]
    brains = tuple(b for _, b, _ in rows)
    bodies = tuple(body for _, _, body in rows)
    tuning = bodies[0].tuning
    # Speeds at and around each threshold, crouched and not, and states the arrays leave to describe_puppet.
    speeds = [0.0, tuning.still_speed, np.nextafter(tuning.still_speed, 0.0), RUN_FRACTION * tuning.max_speed]
    speeds += [np.nextafter(RUN_FRACTION * tuning.max_speed, 0.0), 9.0, float("nan")]
    for i, speed in enumerate(speeds):
        for body, brain, state in ((bodies[i], brains[i], "Locomotion"), (bodies[20 + i], brains[20 + i], "Crouch")):
            body.ground_velocity = np.array([speed, 0.0, 0.0])
            brain.active = state
    for i, state in zip(range(10, 16), ("Jump", "Ragdoll", "Carry", "GetUp", "Wave", ""), strict=True):
        brains[i].active = state
    store = row_store(world)
    assert store.rows(Brain, brains) is not None and store.rows(PuppetBody, bodies) is not None  # the array form runs

    words = describe_puppets(world, entities, brains, bodies)

    assert words == [describe_puppet(world, e, brain) for e, brain in zip(entities, brains, strict=True)]
    gaits = {"standing", "walking", "running", "crouching", "crouch-walking"}
    assert gaits | {"carrying a ball", "getting up", "wave"} <= set(words)
