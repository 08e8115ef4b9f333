"""A generic state machine: states and transitions as data, per-entity runtime state.

The definition (:class:`StateMachine`) is an immutable asset shared by every puppet
that uses it; what changes per step lives in the :class:`Brain` component (active
state, time in it, the cross-fade in progress, the trace of transitions). Per-state
data belongs in the entity's own typed components, not in the brain.

Each step :func:`step_machine`:

1. collects the events raised since the last step (``Brain.raise_event``);
2. evaluates the transitions that leave the active state (and the ``"*"`` ones that
   leave any state) in priority order, highest first; a transition fires when its
   event (if it names one) was raised and its guard (if any) is true;
3. if none fires and the active state's ``fits`` guard says the state no longer fits
   the input, the machine falls back to the *default state* (thesis §6.2.2: the
   ragdoll, "activated when such a situation arises");
4. runs ``exit`` / ``enter`` on a change, then ``update`` of the active state.

Guards and callbacks take ``(world, entity, brain)``; they read the context
(stick, ground, nearby objects) from the world and write the animation request.

:func:`step_machines` steps many entities at once. A crowd is mostly entities in a
common state with nothing happening, so a state may give its guards an *array* form
(``Transition.batch_guard``, ``State.batch_fits``) and its update one
(``State.batch_update``): these run once over every entity in the state, on columns
the caller gathered (the context ``C``), and only the entities an array guard flags,
those with events, and those in states without array forms go through
:func:`step_machine` one by one. An array guard may over-approximate (``True`` means
"evaluate this one in Python"), ``batch_fits`` may under-approximate; so a flagged
entity is simply evaluated exactly, and the result is the same as stepping each alone.
"""

from __future__ import annotations

import operator
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from itertools import repeat
from typing import Any, Generic, TypeVar

import numpy as np
from numpy.typing import NDArray

from engine.arrays import Intp as Rows
from engine.ecs import Entity, World
from engine.rows import RowBlock, keep_in_rows, row_store

__all__ = [
    "ANY",
    "BatchGuard",
    "BatchUpdate",
    "Brain",
    "State",
    "StateMachine",
    "TraceEntry",
    "Transition",
    "step_machine",
    "step_machines",
]

ANY = "*"
C = TypeVar("C")
Callback = Callable[[World, Entity, "Brain"], None]
Guard = Callable[[World, Entity, "Brain"], bool]

BatchGuard = Callable[[World, C, Rows], NDArray[np.bool_]]
"""``(world, columns, rows) -> mask``: the array form of a guard over the entities ``rows`` of the columns."""
BatchUpdate = Callable[[World, C, Rows], None]
"""``(world, columns, rows)``: the array form of a state's update, for entities no transition left."""


def _nothing(world: World, entity: Entity, brain: Brain) -> None:
    return None


def _always(world: World, entity: Entity, brain: Brain) -> bool:
    return True


@dataclass(frozen=True)
class State(Generic[C]):
    """A state's behaviour: ``enter``/``update``/``exit`` callbacks, a ``fits`` guard, and their array forms."""

    name: str
    enter: Callback = _nothing
    update: Callback = _nothing
    exit: Callback = _nothing
    fits: Guard = _always
    description: str = ""
    batch_update: BatchUpdate[C] | None = None
    batch_fits: BatchGuard[C] | None = None


@dataclass(frozen=True)
class Transition(Generic[C]):
    """An edge: from ``source`` (or ``ANY``) to ``target`` on ``event`` and/or when ``guard`` holds.

    ``batch_guard`` is the guard over arrays (see :func:`step_machines`)."""

    source: str
    target: str
    event: str | None = None
    guard: Guard | None = None
    priority: int = 0
    crossfade: float = 0.2
    label: str = ""
    batch_guard: BatchGuard[C] | None = None

    def fires(self, world: World, entity: Entity, brain: Brain, events: Sequence[str]) -> bool:
        """Whether this transition should be taken now."""
        if self.event is not None and self.event not in events:
            return False
        if self.guard is not None and not self.guard(world, entity, brain):
            return False
        return self.event is not None or self.guard is not None


@dataclass
class TraceEntry:
    """One transition taken: when, from where, to where, and why."""

    frame: int
    source: str
    target: str
    reason: str


@dataclass
class Brain:
    """Per-entity runtime state of a state machine (a component)."""

    machine: StateMachine[Any] = field(metadata={"hash": False})
    active: str = ""
    time_in_state: float = 0.0
    crossfade: float = 0.0
    crossfade_total: float = 0.0
    previous: str = ""
    pending_events: list[str] = field(default_factory=list)
    last_events: list[str] = field(default_factory=list)
    trace: list[TraceEntry] = field(default_factory=list)
    max_trace: int = 256

    def raise_event(self, name: str) -> None:
        """Queue an event for the next evaluation."""
        self.pending_events.append(name)

    @property
    def fade_weight(self) -> float:
        """0 just after a transition, rising to 1 when its cross-fade is over."""
        if self.crossfade_total <= 0:
            return 1.0
        return 1.0 - self.crossfade / self.crossfade_total


keep_in_rows(
    Brain,
    machine=("object", (), False),
    active=("object", (), False),
    time_in_state=("float", (), False),
    crossfade=("float", (), False),
)
"""A crowd's machines, states and clocks are arrays (:mod:`engine.rows`): :func:`step_machines` sorts the
brains by state and advances their clocks without touching them one by one."""


class StateMachine(Generic[C]):
    """An immutable graph of states and transitions with a default state."""

    def __init__(
        self,
        name: str,
        states: Sequence[State[C]],
        transitions: Sequence[Transition[C]],
        default: str,
        initial: str | None = None,
    ) -> None:
        self.name = name
        self.states = {s.name: s for s in states}
        if len(self.states) != len(states):
            raise ValueError(f"{name}: state names must be unique")
        for t in transitions:
            for end in (t.source, t.target):
                if end != ANY and end not in self.states:
                    raise ValueError(f"{name}: transition {t.source}->{t.target} names unknown state {end!r}")
            if t.event is None and t.guard is None:
                raise ValueError(f"{name}: transition {t.source}->{t.target} needs an event or a guard")
        if default not in self.states:
            raise ValueError(f"{name}: default state {default!r} is not a state")
        self.default = default
        self.initial = initial or default
        if self.initial not in self.states:
            raise ValueError(f"{name}: initial state {self.initial!r} is not a state")
        self.transitions = tuple(transitions)
        self._outgoing: dict[str, list[Transition[C]]] = {}
        self._batchable: dict[str, bool] = {}
        for s, state in self.states.items():
            out = [t for t in transitions if t.source in (s, ANY) and t.target != s]
            # Highest priority first; among equals, specific before ANY, then declaration order.
            out.sort(key=lambda t: (-t.priority, t.source == ANY))
            self._outgoing[s] = out
            # A state is stepped over arrays only if every way out of it has an array guard
            # (event transitions need no guard: an entity with events is stepped alone).
            self._batchable[s] = (
                state.batch_update is not None
                and (state.fits is _always or state.batch_fits is not None)
                and all(t.batch_guard is not None or t.guard is None for t in out)
            )

    def new_brain(self) -> Brain:
        """A component starting in the initial state (``enter`` runs on the first step)."""
        return Brain(machine=self, active="")

    def outgoing(self, state: str) -> list[Transition[C]]:
        """Transitions leaving ``state``, in evaluation order."""
        return self._outgoing[state]

    def batchable(self, state: str) -> bool:
        """Whether entities in ``state`` can be stepped over arrays (see :func:`step_machines`)."""
        return self._batchable[state]

    def to_dot(self) -> str:
        """The graph in Graphviz DOT: the default state double-circled, edges labelled."""
        lines = [f'digraph "{self.name}" {{', "  rankdir=LR;", '  node [shape=ellipse, fontname="Helvetica"];']
        for s in self.states:
            shape = "doublecircle" if s == self.default else "ellipse"
            lines.append(f'  "{s}" [shape={shape}];')
        for t in self.transitions:
            label = t.label or t.event or (t.guard.__name__ if t.guard else "")
            sources = list(self.states) if t.source == ANY else [t.source]
            for src in sources:
                if src != t.target:
                    style = ", style=dashed" if t.source == ANY else ""
                    lines.append(f'  "{src}" -> "{t.target}" [label="{label}"{style}];')
        lines.append("}")
        return "\n".join(lines)


def _switch(world: World, entity: Entity, brain: Brain, target: str, reason: str, crossfade: float) -> None:
    machine = brain.machine
    if brain.active:
        machine.states[brain.active].exit(world, entity, brain)
    brain.trace.append(TraceEntry(world.frame, brain.active or "-", target, reason))
    if len(brain.trace) > brain.max_trace:
        del brain.trace[: len(brain.trace) - brain.max_trace]
    brain.previous, brain.active = brain.active, machine.states[target].name
    brain.time_in_state = 0.0
    brain.crossfade = brain.crossfade_total = crossfade
    machine.states[target].enter(world, entity, brain)


def step_machine(world: World, entity: Entity, brain: Brain) -> None:
    """Advance one entity's machine by one fixed step (see the module docstring)."""
    machine = brain.machine
    events, brain.pending_events = brain.pending_events, []
    if events:
        brain.last_events = (brain.last_events + events)[-8:]
    if not brain.active:
        _switch(world, entity, brain, machine.initial, "start", 0.0)
    else:
        for t in machine.outgoing(brain.active):
            if t.fires(world, entity, brain, events):
                _switch(world, entity, brain, t.target, t.label or t.event or "guard", t.crossfade)
                break
        else:
            if brain.active != machine.default and not machine.states[brain.active].fits(world, entity, brain):
                _switch(world, entity, brain, machine.default, "no state fits", 0.2)
    machine.states[brain.active].update(world, entity, brain)
    brain.time_in_state += world.dt
    brain.crossfade = max(0.0, brain.crossfade - world.dt)


def _quiet_rows(world: World, machine: StateMachine[C], state: str, columns: C, rows: Rows) -> NDArray[np.bool_]:
    """Which of ``rows`` (all in ``state``, without events) certainly stay in it: no array guard flags them."""
    stay = np.ones(len(rows), dtype=bool)
    for t in machine.outgoing(state):
        if t.batch_guard is not None:
            stay &= ~t.batch_guard(world, columns, rows)
    fits = machine.states[state].batch_fits
    if fits is not None:
        stay &= fits(world, columns, rows)
    return stay


def step_machines(world: World, entities: Sequence[Entity], brains: Sequence[Brain], columns: C) -> None:
    """Advance many entities' machines by one step: over arrays where nothing happens, one by one elsewhere.

    ``columns`` is what the array guards and updates of the machine read (gathered by the
    caller, row ``i`` for ``entities[i]``). The entities stepped one by one go in entity
    order, after the array updates; an array guard or update must therefore read and
    write only its own entities' components (what :func:`step_machine` of another
    entity changes cannot decide it).
    """
    block = row_store(world).block(Brain, brains) if isinstance(brains, tuple) and brains else None
    if block is not None and block.stale:
        block = None
    groups, single = _groups(brains, block)
    dt = world.dt
    for (_, state), members in groups.items():
        rows = np.array(members, dtype=np.intp)
        machine = brains[members[0]].machine
        stay = _quiet_rows(world, machine, state, columns, rows)
        quiet = rows[stay]
        single.extend(rows[~stay].tolist())
        if len(quiet):
            update = machine.states[state].batch_update
            assert update is not None  # batchable() checked it
            update(world, columns, quiet)
            if block is not None and not block.stale:
                _tick(block, quiet if len(quiet) < len(brains) else _ALL, dt)
            else:
                for brain in brains if len(quiet) == len(brains) else [brains[i] for i in quiet.tolist()]:
                    brain.time_in_state += dt
                    fade = brain.crossfade
                    # max(0.0, fade - dt), which is 0.0 whenever fade is not positive (NaN included)
                    brain.crossfade = max(0.0, fade - dt) if fade > 0.0 else 0.0
    for i in sorted(single):
        step_machine(world, entities[i], brains[i])


_ALL = slice(None)


def _tick(block: RowBlock, rows: Rows | slice, dt: float) -> None:
    """The clocks of the brains at ``rows`` of a row block, as :func:`step_machine` advances one: the same
    operations on the same float64 numbers (Python's ``max(0.0, x)`` is ``x`` only where ``x > 0``: a NaN
    gives +0.0, where ``np.maximum`` would keep it)."""
    time = block.arrays["time_in_state"]
    time[rows] += dt
    fade = block.arrays["crossfade"]
    f = fade[rows]
    left = f - dt
    fade[rows] = np.where(f > 0.0, np.where(left > 0.0, left, 0.0), 0.0)


_KEYS = operator.attrgetter("pending_events", "machine", "active")
_PENDING = operator.attrgetter("pending_events")


def _groups(
    brains: Sequence[Brain], block: RowBlock | None = None
) -> tuple[dict[tuple[int, str], list[int]], list[int]]:
    """The rows that may go over arrays, by (machine, active state) in order of first appearance, and the others.

    A crowd shares one machine and has no events most steps: then the rows are sorted by
    state in a few C-level passes instead of a test per entity; with the brains' row ``block``
    (row ``i`` for ``brains[i]``) their machines and states are read from its arrays."""
    groups: dict[tuple[int, str], list[int]] = {}
    single: list[int] = []
    machine = brains[0].machine if brains else None
    pending: Sequence[Any]
    machines: Iterable[Any]
    actives: Sequence[str]
    if block is not None:
        pending = () if not any(map(_PENDING, brains)) else (True,)
        machines, actives = block.arrays["machine"], block.arrays["active"].tolist()
    else:
        # One pass over the brains (each a cold object in a crowd), then C-level passes over the tuples.
        pending, machines, actives = zip(*map(_KEYS, brains)) if brains else ((), (), ())
    if machine is None or any(pending) or not all(map(operator.is_, machines, repeat(machine))):
        for i, brain in enumerate(brains):
            if brain.active and not brain.pending_events and brain.machine.batchable(brain.active):
                groups.setdefault((id(brain.machine), brain.active), []).append(i)
            else:
                single.append(i)
        return groups, single
    states = dict.fromkeys(actives)
    for state in states:
        members = list(range(len(actives))) if len(states) == 1 else [i for i, a in enumerate(actives) if a == state]
        if state and machine.batchable(state):
            groups[(id(machine), state)] = members
        else:
            single.extend(members)
    return groups, single
