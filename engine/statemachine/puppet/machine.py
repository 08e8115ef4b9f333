"""The puppet's state machine (thesis Fig. 6.6), as data.

States: Locomotion (idle/walk/run), Crouch, Jump, Land, Ragdoll (the default),
GetUp, PickUp, Carry, PutDown, RollSnowball. Every state is defined by the
callbacks of its module; this file only wires the graph: which event or guard
leads where, with which priority and cross-fade.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from engine.statemachine.machine import State, StateMachine, Transition
from engine.statemachine.puppet import fall_states as fall
from engine.statemachine.puppet import ground_states as ground
from engine.statemachine.puppet import jump_state as jump
from engine.statemachine.puppet import object_states as obj

__all__ = ["puppet_machine", "STATE_NAMES"]

STATE_NAMES = ("Locomotion", "Crouch", "Jump", "Land", "Ragdoll", "GetUp", "PickUp", "Carry", "PutDown", "RollSnowball")


if TYPE_CHECKING:
    from engine.ecs import Entity, World
    from engine.statemachine.machine import Brain


def _always(world: World, entity: Entity, brain: Brain) -> bool:
    return True


def puppet_machine() -> StateMachine:
    """The graph every puppet (and every snowman) runs."""
    states = [
        State("Locomotion", update=ground.update_locomotion, fits=ground.locomotion_fits,
              description="idle / walk / run from the blend space; follows the stick"),
        State("Crouch", update=ground.update_crouch, fits=ground.locomotion_fits,
              description="crouch idle / crouch walk; hips as low as the stick holds them"),
        State("Jump", enter=jump.enter_jump, update=jump.update_jump, exit=jump.exit_jump,
              description="anticipation squat, then the tracked arc (Eq. 6.3)"),
        State("Land", enter=jump.enter_land, update=jump.update_land, description="absorbing crouch"),
        State("Ragdoll", enter=fall.enter_ragdoll, update=fall.update_ragdoll,
              description="default state: limp physics, hangs from the stick when held"),
        State("GetUp", enter=fall.enter_getup, update=fall.update_getup, exit=fall.exit_getup,
              description="blend from the lying pose into the get-up clip"),
        State("PickUp", enter=obj.enter_pickup, update=obj.update_pickup, description="hands reach a small ball and lift it"),
        State("Carry", update=obj.update_carry, exit=obj.exit_carry, fits=ground.locomotion_fits, description="walk holding the ball"),
        State("PutDown", enter=obj.enter_putdown, update=obj.update_putdown, exit=obj.exit_putdown,
              description="lower the ball, onto another ball if one is in front"),
        State("RollSnowball", enter=obj.enter_roll, update=obj.update_roll, exit=obj.exit_roll, fits=ground.locomotion_fits,
              description="crouch walk, both hands on the ball, pushing it"),
    ]
    t = [
        # Jumps first: a flick wins over everything on the ground.
        Transition("Locomotion", "Jump", guard=jump.jump_wanted, priority=20, crossfade=0.1, label="flick"),
        Transition("Crouch", "Jump", guard=jump.jump_wanted, priority=20, crossfade=0.1, label="flick"),
        Transition("Jump", "Ragdoll", event="jump_invalid", priority=30, crossfade=0.1),
        Transition("Jump", "Land", event="landed", priority=25, crossfade=0.1),
        Transition("Land", "Locomotion", guard=jump.landing_done, crossfade=0.15, label="absorbed"),
        Transition("Locomotion", "Crouch", guard=ground.wants_crouch, priority=5, crossfade=0.25, label="lowered"),
        Transition("Crouch", "Locomotion", guard=ground.wants_stand, priority=5, crossfade=0.25, label="raised"),
        Transition("Crouch", "PickUp", guard=obj.can_pick_up, priority=10, crossfade=0.2, label="still over a small ball"),
        Transition("Crouch", "RollSnowball", guard=obj.can_roll, priority=8, crossfade=0.2, label="pushes a ball"),
        Transition("PickUp", "Carry", guard=obj.pickup_done, crossfade=0.2, label="lifted"),
        Transition("Carry", "PutDown", guard=obj.wants_putdown, priority=5, crossfade=0.2, label="lowered"),
        Transition("PutDown", "Locomotion", guard=obj.putdown_done, crossfade=0.2, label="set down"),
        Transition("RollSnowball", "Locomotion", guard=obj.stop_rolling, priority=5, crossfade=0.25, label="stood up"),
        Transition("Ragdoll", "GetUp", guard=fall.ragdoll_settled, crossfade=0.0, label="settled"),
        Transition("GetUp", "Locomotion", guard=fall.getup_done, crossfade=0.2, label="standing"),
    ]
    return StateMachine("puppet", states, t, default="Ragdoll", initial="Locomotion")
