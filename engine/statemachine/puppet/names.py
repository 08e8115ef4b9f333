"""The names of the puppet's built-in states and events, as enums.

They are ``StrEnum``: the generic machine keys states and events by string (a state
added by another module names itself), recordings and traces print the plain name, and
``brain.active == PuppetState.CARRY`` is checked by the type checker where a misspelt
``"Cary"`` was not.
"""

from __future__ import annotations

from enum import StrEnum

__all__ = ["PuppetEvent", "PuppetState"]


class PuppetState(StrEnum):
    """The states of thesis Fig. 6.6 (see :mod:`~engine.statemachine.puppet.machine`)."""

    LOCOMOTION = "Locomotion"
    CROUCH = "Crouch"
    JUMP = "Jump"
    LAND = "Land"
    RAGDOLL = "Ragdoll"
    GET_UP = "GetUp"
    PICK_UP = "PickUp"
    CARRY = "Carry"
    PUT_DOWN = "PutDown"
    ROLL_SNOWBALL = "RollSnowball"


class PuppetEvent(StrEnum):
    """Events the puppet's states raise for the machine."""

    LANDED = "landed"
    JUMP_INVALID = "jump_invalid"
