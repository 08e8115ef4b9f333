"""The state hash of a recorded step with 100 puppets: packed columns against field by field.

The scene is the sandbox with 100 puppets standing in a grid, stepped for one
second so every component, the brains' traces and the physics world are filled
in. The baseline is :func:`field_by_field_hash`, the hash as it was before
:mod:`engine.hashing` packed columns: every value of every component fed to the
digest on its own, in Python. It is kept here as the reference the figure's ratio
is taken against (a test also checks that it and the packed hash see the same
changes).
"""

from __future__ import annotations

import hashlib

from engine.app import App
from engine.ecs import World
from engine.hashing import feed, state_hash
from puppetphone.bench.figures import Figure, median_time

__all__ = ["run", "crowd_app", "field_by_field_hash", "PUPPETS"]

PUPPETS = 100


def field_by_field_hash(world: World) -> str:
    """The hash before packing: entity by entity, component by component, value by value."""
    h = hashlib.blake2b(digest_size=16)
    feed(h, world.frame)
    feed(h, world.rng.bit_generator.state)
    for e in world.entities():
        feed(h, e)
        for comp in world.components_of(e):
            if getattr(comp, "SIM_STATE", True):
                feed(h, comp)
    for res in world.resources():
        if getattr(res, "SIM_STATE", False):
            feed(h, res)
    return h.hexdigest()


def crowd_app(puppets: int = PUPPETS, seed: int = 0, steps: int = 60) -> App:
    """The sandbox with ``puppets`` puppets in rows of ten, stepped ``steps`` times."""
    from engine.statemachine.puppet import spawn_puppet
    from input.hub import InputHub
    from puppetphone.games import make_app

    app = make_app("sandbox", seed, InputHub())
    for i in range(puppets - 1):
        spawn_puppet(app.world, (1.5 * (i % 10 + 1), 0.0, 1.5 * (i // 10)), 0.3 * i, name=f"puppet{i + 1}")
    app.run_steps(steps)
    return app


def run() -> list[Figure]:
    """Microseconds per state hash of the 100-puppet world, packed vs field by field."""
    world = crowd_app().world
    packed = median_time(lambda: state_hash(world), repeats=21)
    by_field = median_time(lambda: field_by_field_hash(world), repeats=11)
    return [Figure("state-hash", "state_hash_us_100_puppets", packed * 1e6, "us", "field by field", by_field * 1e6)]
