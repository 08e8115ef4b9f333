"""State machines as data (STYLE: states with enter/update/exit, transitions with a
guard, priority and cross-fade time, and a trace of transitions), stepped one entity
at a time or a crowd at once over arrays."""

from engine.statemachine.machine import (
    ANY,
    BatchGuard,
    BatchUpdate,
    Brain,
    State,
    StateMachine,
    TraceEntry,
    Transition,
    step_machine,
    step_machines,
)

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
