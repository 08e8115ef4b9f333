"""The puppet's state machine (thesis Fig. 6.6), assembled from its state modules.

States: Locomotion (idle/walk/run), Crouch, Jump, Land, Ragdoll (the default),
GetUp, PickUp, Carry, PutDown, RollSnowball. Each state module exports a
:class:`~engine.statemachine.puppet.spec.StateSpec` — its states' callbacks and the
transitions it owns, with their priorities and cross-fades; this file only lists the
modules. A game adds a state of its own with ``puppet_machine(extra=(its_module.SPEC,))``.
"""

from __future__ import annotations

from collections.abc import Sequence

from engine.statemachine.machine import StateMachine
from engine.statemachine.puppet import fall_states, ground_states, jump_state, object_states
from engine.statemachine.puppet.names import PuppetState
from engine.statemachine.puppet.spec import PuppetColumns, StateSpec

__all__ = ["BUILT_IN", "STATE_NAMES", "puppet_machine"]

BUILT_IN: tuple[StateSpec, ...] = (ground_states.SPEC, jump_state.SPEC, fall_states.SPEC, object_states.SPEC)
"""The state modules every puppet runs, in the order their transitions are declared."""

STATE_NAMES = tuple(PuppetState)


def puppet_machine(extra: Sequence[StateSpec] = ()) -> StateMachine[PuppetColumns]:
    """The graph every puppet (and every snowman) runs, with the states of ``extra`` registered beside them."""
    specs = (*BUILT_IN, *extra)
    states = [s for spec in specs for s in spec.states]
    transitions = [t for spec in specs for t in spec.transitions]
    return StateMachine("puppet", states, transitions, default=PuppetState.RAGDOLL, initial=PuppetState.LOCOMOTION)
