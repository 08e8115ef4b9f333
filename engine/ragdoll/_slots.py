"""What the physics world keeps per ragdoll and per prop, beside MuJoCo's own state."""

from __future__ import annotations

from dataclasses import dataclass

from engine.arrays import F64 as _F
from engine.ragdoll._control import Command
from engine.ragdoll.mjcf import PropSpec, RagdollSpec

__all__ = ["RagdollSlot", "PropSlot"]


@dataclass
class RagdollSlot:
    """One ragdoll: how to build it, its command, and whether (and how) it is in the model now."""

    spec: RagdollSpec
    cmd: Command
    reach: float
    kind: bytes  # which pool slots fit it (:func:`engine.ragdoll._pool.kind_of`)
    joints: int  # its skeleton's joint count (read for every puppet every step)
    placed: bool = False
    in_model: bool = False  # simulated this step (animated and alone: left out, see _islands)
    pool: int = -1  # the pool slot lent to it while in the model
    prev: tuple[_F, _F] | None = None  # out of the model: the target before the last step's
    ghost: bool = False  # inside another ragdoll: touches only the ground and props


@dataclass
class PropSlot:
    """One prop: how to build it, its starting state until built, and its MuJoCo addresses."""

    spec: PropSpec
    init: tuple[_F, _F, _F] | None = None
    qadr: int = -1
    dadr: int = -1
    geom: int = -1
    body: int = -1
