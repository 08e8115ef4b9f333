"""State machines as data (STYLE: states with enter/update/exit, transitions with a
guard, priority and cross-fade time, and a trace of transitions)."""

from engine.statemachine.machine import ANY, Brain, State, StateMachine, TraceEntry, Transition, step_machine

__all__ = ["ANY", "Brain", "State", "StateMachine", "TraceEntry", "Transition", "step_machine"]
