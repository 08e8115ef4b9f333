"""The puppet's brain: the states of thesis Fig. 6.6 wired into one state machine.

``install_puppets(app)`` adds everything a living puppet needs; ``spawn_puppet``
creates one. See :mod:`~engine.statemachine.puppet.machine` for the graph and
:mod:`~engine.statemachine.puppet.spec` for how a state is declared and registered.
"""

from engine.statemachine.puppet.body import (
    GettingUp,
    Handling,
    Jumping,
    JumpPhase,
    Landing,
    PoseOverride,
    PuppetBody,
    PuppetTuning,
)
from engine.statemachine.puppet.machine import BUILT_IN, STATE_NAMES, puppet_machine
from engine.statemachine.puppet.names import PuppetEvent, PuppetState
from engine.statemachine.puppet.plugin import PuppetMachine, brain_system, install_puppets, spawn_puppet
from engine.statemachine.puppet.spec import PuppetColumns, StateSpec

__all__ = [
    "BUILT_IN",
    "STATE_NAMES",
    "GettingUp",
    "Handling",
    "JumpPhase",
    "Jumping",
    "Landing",
    "PoseOverride",
    "PuppetBody",
    "PuppetColumns",
    "PuppetEvent",
    "PuppetMachine",
    "PuppetState",
    "PuppetTuning",
    "StateSpec",
    "brain_system",
    "install_puppets",
    "puppet_machine",
    "spawn_puppet",
]
