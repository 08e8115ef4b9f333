"""Adding a state is one module plus its registration, and the crowd's array path changes nothing.

``wave_state.py`` is a state the engine does not know; registering it with
``puppet_machine(extra=...)`` is all it takes for a puppet to enter it on its event,
run it, and leave it by its own guard, while the other puppets walk on.

The array path (:func:`~engine.statemachine.machine.step_machines`) is compared with
stepping every puppet alone (``sense`` + ``step_machine``, the path before it) on the
same crowd, state hash by state hash. Shown to fail when broken: ``follow_released``
without the braking stiffness, or the batched puppets' ``time_in_state`` not advanced.
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest

from engine.ecs import World
from engine.hashing import state_hash
from engine.statemachine import Brain, step_machine
from engine.statemachine.puppet import PuppetBody, PuppetMachine, PuppetState, puppet_machine, spawn_puppet
from engine.statemachine.puppet import plugin as puppet_plugin
from engine.statemachine.puppet.senses import sense
from input.hub import InputHub
from puppetphone.games import make_app

_spec = importlib.util.spec_from_file_location("wave_state", Path(__file__).with_name("wave_state.py"))
assert _spec is not None and _spec.loader is not None
wave = importlib.util.module_from_spec(_spec)
sys.modules[_spec.name] = wave  # a dataclass looks its module up while it is defined
_spec.loader.exec_module(wave)


def test_a_registered_state_is_entered_run_and_left() -> None:
    app = make_app("sandbox", 3, InputHub([]), {"scene": "empty", "puppets": 1})
    world = app.world
    assert wave.WAVE not in world.resource(PuppetMachine).machine.states  # not built in
    world.insert_resource(PuppetMachine(puppet_machine(extra=(wave.SPEC,))))
    e = spawn_puppet(world, (2.0, 0.0, 0.0), extra=(wave.Waving(),))
    app.run_steps(10)
    brain = world.get(e, Brain)
    assert brain.active == PuppetState.LOCOMOTION
    brain.raise_event(wave.WAVE_EVENT)
    app.step()
    assert brain.active == wave.WAVE
    steps = 0
    while brain.active == wave.WAVE:
        app.step()
        steps += 1
    assert steps == pytest.approx(wave.WAVE_TIME / world.dt, abs=1)
    assert [(t.source, t.target, t.reason) for t in brain.trace[-2:]] == [
        (PuppetState.LOCOMOTION, wave.WAVE, wave.WAVE_EVENT),
        (wave.WAVE, PuppetState.LOCOMOTION, "waved"),
    ]


def _one_by_one(world: World) -> None:
    """The brain stage as it was before the array path: sense and step each puppet in turn."""
    for e, body, brain in world.query(PuppetBody, Brain):
        sense(world, e, body)
        step_machine(world, e, brain)


def _crowd(seed: int):  # type: ignore[no-untyped-def]
    app = make_app("sandbox", seed, InputHub([]), {"puppets": 8})
    app.run_steps(5)
    # Some puppets just let go while moving: the spring brakes them and they turn as they stop.
    rng = np.random.default_rng(seed)
    for i, (_, body) in enumerate(app.world.query(PuppetBody)):
        if i % 3 == 0:
            body.walk_velocity = rng.normal(size=3) * np.array([1.5, 0.0, 1.5])
            body.walk_rate = rng.normal(size=3) * np.array([4.0, 0.0, 4.0])
    return app


def test_the_array_path_steps_a_crowd_exactly_as_one_by_one(monkeypatch: pytest.MonkeyPatch) -> None:
    batched = _crowd(4)
    monkeypatch.setattr(puppet_plugin, "brain_system", _one_by_one)  # what install_puppets registers
    single = _crowd(4)
    assert _one_by_one in single.systems("statemachine") and _one_by_one not in batched.systems("statemachine")
    for step in range(60):
        batched.step()
        single.step()
        assert state_hash(batched.world) == state_hash(single.world), f"differs at step {step}"
    moved = [b.heading for _, b in batched.world.query(PuppetBody)]
    assert len(set(moved)) > 5  # the crowd did walk and turn


def test_a_crowd_at_rest_steps_exactly_as_one_by_one(monkeypatch: pytest.MonkeyPatch) -> None:
    """Nobody ever held these puppets: their springs sit at exact rest and the array path skips the
    spring step (``follow._at_rest``); the state is still the one-by-one path's, bit for bit.
    Fails if the rest shortcut left a spring or its history unwritten that the step would change,
    or skipped the speed and facing of the puppets."""
    from engine.statemachine.puppet import follow

    rested: list[bool] = []
    at_rest = follow._at_rest

    def spy(*args):  # type: ignore[no-untyped-def]
        rested.append(at_rest(*args))
        return rested[-1]

    monkeypatch.setattr(follow, "_at_rest", spy)
    batched = make_app("sandbox", 6, InputHub([]), {"puppets": 8})
    monkeypatch.setattr(puppet_plugin, "brain_system", _one_by_one)
    single = make_app("sandbox", 6, InputHub([]), {"puppets": 8})
    for step in range(40):
        batched.step()
        single.step()
        assert state_hash(batched.world) == state_hash(single.world), f"differs at step {step}"
    assert rested and all(rested)


def test_the_rest_shortcut_needs_every_number_at_plus_zero() -> None:
    """-0.0, a tiny velocity or a bad stiffness is not rest (the spring step would change them)."""
    from engine.statemachine.puppet.follow import _at_rest

    z, h, w = np.zeros((4, 3)), np.zeros((4, 12, 3)), np.full(4, 40.0)
    assert _at_rest(z, z, h, w, 1 / 60)
    negative = z.copy()
    negative[2, 1] = -0.0
    assert not _at_rest(negative, z, h, w, 1 / 60)
    assert not _at_rest(z, z + 1e-300, h, w, 1 / 60)
    late = h.copy()
    late[0, 0, 0] = 1e-9
    assert not _at_rest(z, z, late, w, 1 / 60)
    assert not _at_rest(z, z, h, np.array([40.0, np.nan, 40.0, 40.0]), 1 / 60)
    assert not _at_rest(z, z, h, np.array([40.0, -1e9, 40.0, 40.0]), 1 / 60)


def _stir(world: World, rng: np.random.Generator, stick: int) -> None:
    """The same random interference in both worlds: a stick grabbing and dragging a puppet, headings
    and clocks set from outside (signed zeros, NaN, an ``np.float64`` the row blocks cannot hold)."""
    from engine.components import Stick, Transform
    from engine.statemachine.puppet import Handling

    rows = world.query(PuppetBody, Brain, Handling, Transform)
    s = world.get(stick, Stick)
    if rng.random() < 0.3:
        e, _, _, _, tr = rows[int(rng.integers(len(rows)))]
        s.grabbed = e
        s.tip = tr.position + np.array([rng.normal(), 0.95 + 0.4 * rng.normal(), rng.normal()])
        s.velocity = rng.normal(size=3)
    elif rng.random() < 0.3:
        s.grabbed = None
    for _ in range(3):
        _, body, brain, handling, _ = rows[int(rng.integers(len(rows)))]
        pick = rng.random()
        if pick < 0.25:
            body.heading = float(rng.choice([rng.normal(), -0.0, np.pi]))
        elif pick < 0.5:
            brain.crossfade = float(rng.choice([0.1, -0.0, -0.5, np.nan, 0.0]))
        elif pick < 0.7:
            brain.time_in_state = float(rng.normal())
        elif pick < 0.8:
            handling.left = int(rows[0][0])
        elif pick < 0.85:
            body.heading = np.float64(rng.normal())  # type: ignore[assignment]  # unlinks: the plain path again
        else:
            body.walk_velocity = rng.normal(size=3) * np.array([1.0, 0.0, 1.0])


@pytest.mark.parametrize("seed", [11, 12, 13])
def test_a_stirred_crowd_steps_over_arrays_exactly_as_one_by_one(seed: int, monkeypatch: pytest.MonkeyPatch) -> None:
    """A random crowd, held, let go and set from outside each step: the row-block path (``engine.rows``:
    senses, clocks, the released-puppet update, wandering) stays the one-by-one path, bit for bit."""
    from engine.components import Stick

    def make():  # type: ignore[no-untyped-def]
        app = make_app("sandbox", seed, InputHub([]), {"puppets": 24})
        return app, app.world.spawn(Stick())

    batched, bstick = make()
    monkeypatch.setattr(puppet_plugin, "brain_system", _one_by_one)
    single, sstick = make()
    rb, rs = np.random.default_rng(seed), np.random.default_rng(seed)
    for step in range(45):
        _stir(batched.world, rb, bstick)
        _stir(single.world, rs, sstick)
        batched.step()
        single.step()
        assert state_hash(batched.world) == state_hash(single.world), f"differs at step {step}"
