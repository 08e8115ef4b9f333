"""The puppet's brain: the states of thesis Fig. 6.6 wired into one state machine.

``install_puppets(app)`` adds everything a living puppet needs; ``spawn_puppet``
creates one. See :mod:`~engine.statemachine.puppet.machine` for the graph.
"""

from engine.statemachine.puppet.body import PoseOverride, PuppetBody, PuppetTuning
from engine.statemachine.puppet.machine import STATE_NAMES, puppet_machine
from engine.statemachine.puppet.plugin import PuppetMachine, brain_system, install_puppets, spawn_puppet

__all__ = [
    "PoseOverride", "PuppetBody", "PuppetTuning", "STATE_NAMES", "puppet_machine",
    "PuppetMachine", "brain_system", "install_puppets", "spawn_puppet",
]
