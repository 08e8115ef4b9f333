"""The generic state machine: events, guards, priority, default state, trace, DOT."""

from dataclasses import dataclass

import numpy as np
import pytest

from engine.ecs import World
from engine.hashing import state_hash
from engine.statemachine import ANY, Brain, State, StateMachine, Transition, step_machine


@dataclass
class Speed:
    """The toy machine's context: a typed component its guards read."""

    value: float = 0.0


def _world() -> tuple[World, int]:
    w = World()
    return w, w.spawn(Speed())


def make_machine(log):
    def enter(name):
        return lambda w, e, b: log.append(("enter", name))

    def exit_(name):
        return lambda w, e, b: log.append(("exit", name))

    def high_speed(w, e, b):
        return w.get(e, Speed).value > 2.0

    states = [
        State("ragdoll", enter("ragdoll"), exit=exit_("ragdoll")),
        State("idle", enter("idle"), exit=exit_("idle")),
        State("run", enter("run"), exit=exit_("run"), fits=lambda w, e, b: w.get(e, Speed).value < 10),
        State("jump", enter("jump")),
    ]
    transitions = [
        Transition("ragdoll", "idle", event="landed", crossfade=0.5),
        Transition("idle", "run", guard=high_speed, crossfade=0.25),
        Transition("idle", "jump", event="flick", priority=5),
        Transition(ANY, "ragdoll", event="hit", priority=10, label="hit"),
    ]
    return StateMachine("test", states, transitions, default="ragdoll", initial="idle")


def test_starts_in_initial_state_and_follows_guard():
    log = []
    m = make_machine(log)
    w, e = _world()
    b = m.new_brain()
    step_machine(w, e, b)
    assert b.active == "idle" and log == [("enter", "idle")]
    w.get(e, Speed).value = 3.0
    step_machine(w, e, b)
    assert b.active == "run"
    assert b.crossfade_total == 0.25 and b.fade_weight < 0.5
    assert [(t.source, t.target) for t in b.trace] == [("-", "idle"), ("idle", "run")]


def test_priority_event_beats_guard():
    m = make_machine([])
    w, e = _world()
    b = m.new_brain()
    step_machine(w, e, b)
    w.get(e, Speed).value = 3.0
    b.raise_event("flick")
    step_machine(w, e, b)
    assert b.active == "jump"


def test_any_transition_and_default_state_when_nothing_fits():
    m = make_machine([])
    w, e = _world()
    b = m.new_brain()
    step_machine(w, e, b)
    w.get(e, Speed).value = 3.0
    step_machine(w, e, b)
    w.get(e, Speed).value = 50.0  # run no longer fits and no transition applies
    step_machine(w, e, b)
    assert b.active == "ragdoll" and b.trace[-1].reason == "no state fits"
    b.raise_event("landed")
    step_machine(w, e, b)
    assert b.active == "idle"
    b.raise_event("hit")
    step_machine(w, e, b)
    assert b.active == "ragdoll" and b.trace[-1].reason == "hit"
    assert b.last_events[-2:] == ["landed", "hit"]


def test_bad_definitions_refused():
    with pytest.raises(ValueError, match="unknown state"):
        StateMachine("x", [State("a")], [Transition("a", "b", event="e")], default="a")
    with pytest.raises(ValueError, match="event or a guard"):
        StateMachine("x", [State("a"), State("b")], [Transition("a", "b")], default="a")
    with pytest.raises(ValueError, match="default"):
        StateMachine("x", [State("a")], [], default="z")


def test_dot_export_lists_states_and_edges():
    dot = make_machine([]).to_dot()
    assert '"ragdoll" [shape=doublecircle]' in dot
    assert '"idle" -> "jump" [label="flick"]' in dot
    assert '"run" -> "ragdoll" [label="hit", style=dashed]' in dot


def test_brain_is_hashable_state():
    m = make_machine([])
    w = World()
    e = w.spawn(m.new_brain())
    h0 = state_hash(w)
    step_machine(w, e, w.get(e, type(m.new_brain())))
    assert state_hash(w) != h0


def test_step_machines_steps_quiet_entities_over_arrays_and_the_rest_alone() -> None:
    """Entities an array guard flags, and those with events, take their transitions as alone; the
    others get the array update once, together. Fails if flagged rows were array-updated, if the
    event were missed, or if the array update ran per entity."""
    import numpy as np

    from engine.statemachine import step_machines

    calls: list[list[int]] = []

    def fast(w, cols, rows):  # type: ignore[no-untyped-def]
        return cols[rows] > 2.0  # over-approximates high_speed: it is only a filter

    states = [
        State("ragdoll"),
        State("idle", batch_update=lambda w, cols, rows: calls.append([int(r) for r in rows])),
        State("run"),
        State("jump"),
    ]
    transitions = [
        Transition("idle", "run", guard=lambda w, e, b: w.get(e, Speed).value > 2.0, batch_guard=fast),
        Transition("idle", "jump", event="flick"),
    ]
    m = StateMachine("arrays", states, transitions, default="ragdoll", initial="idle")
    assert m.batchable("idle") and not m.batchable("run")
    w = World()
    speeds = [0.0, 3.0, 1.0, 0.5]
    es = [w.spawn(Speed(v)) for v in speeds]
    bs = [m.new_brain() for _ in es]
    cols = np.array(speeds)
    step_machines(w, es, bs, cols)  # the first step enters the initial state, one by one
    assert [b.active for b in bs] == ["idle"] * 4 and calls == []
    bs[3].raise_event("flick")
    step_machines(w, es, bs, cols)
    assert [b.active for b in bs] == ["idle", "run", "idle", "jump"]
    assert calls == [[0, 2]]
    assert bs[0].time_in_state == pytest.approx(2 * w.dt) and bs[1].time_in_state == pytest.approx(w.dt)


def test_step_machines_groups_a_shared_machine_as_the_entity_by_entity_rule() -> None:
    """The crowd's shortcut (one machine, no events: rows sorted by state in C-level passes) groups
    exactly as the rule it replaces, taken entity by entity. Fails if the shortcut merged
    states, lost their order of first appearance, or batched a state that cannot be."""
    import random

    from engine.statemachine.machine import _groups

    states = [State("a", batch_update=lambda w, c, r: None), State("b"), State("c", batch_update=lambda w, c, r: None)]
    m = StateMachine("m", states, [Transition("a", "b", event="go")], default="b", initial="a")
    other = StateMachine("o", states, [], default="b", initial="a")
    rng = random.Random(3)
    for trial in range(200):
        brains = [m.new_brain() for _ in range(rng.randint(0, 12))]
        for b in brains:
            b.active = rng.choice(["a", "b", "c", ""])
            if trial % 3 == 0 and rng.random() < 0.2:
                b.raise_event("go")
            if trial % 5 == 0 and rng.random() < 0.2:
                b.machine = other
        want: dict[tuple[int, str], list[int]] = {}
        alone: list[int] = []
        for i, b in enumerate(brains):
            if b.active and not b.pending_events and b.machine.batchable(b.active):
                want.setdefault((id(b.machine), b.active), []).append(i)
            else:
                alone.append(i)
        groups, single = _groups(brains)
        assert list(groups.items()) == list(want.items())
        assert sorted(single) == alone


def test_the_clocks_of_a_row_block_tick_as_step_machine_ticks_one() -> None:
    """``_tick`` (the brains' clocks over arrays) gives the bits of ``step_machine``'s
    ``time_in_state += dt`` and ``crossfade = max(0.0, crossfade - dt)``, signed zeros, NaN and
    infinities included. Fails with ``fade[rows] = np.maximum(left, 0.0)`` (a NaN cross-fade stays
    NaN) or with the clocks of every row advanced, not only ``rows``'."""
    from engine.rows import RowStore
    from engine.statemachine.machine import _tick

    rng = np.random.default_rng(5)
    specials = [0.0, -0.0, np.nan, np.inf, -np.inf, 1 / 60, 1 / 60 + 1e-17, 5e-324, -1.0]
    dt = 1 / 60
    m = StateMachine("m", [State("a")], [], default="a")
    for _ in range(20):
        brains = [m.new_brain() for _ in range(30)]
        for b in brains:
            b.time_in_state = float(rng.choice(specials)) if rng.random() < 0.4 else float(rng.normal())
            b.crossfade = float(rng.choice(specials)) if rng.random() < 0.6 else float(rng.normal())
        expected = [(b.time_in_state + dt, max(0.0, b.crossfade - dt) if b.crossfade > 0.0 else 0.0) for b in brains]
        before = [(b.time_in_state, b.crossfade) for b in brains]
        block = RowStore().block(Brain, tuple(brains))
        rows = np.flatnonzero(rng.random(len(brains)) < 0.7)
        _tick(block, rows, dt)
        for i, b in enumerate(brains):
            want = expected[i] if i in rows else before[i]
            got = (b.time_in_state, b.crossfade)
            assert np.array(got).tobytes() == np.array(want).tobytes(), (i, got, want)
