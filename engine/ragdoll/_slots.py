"""What the physics world keeps per ragdoll and per prop, beside MuJoCo's own state and the
ragdolls' command columns (:mod:`engine.ragdoll._commands`)."""

from __future__ import annotations

from dataclasses import dataclass

from engine.arrays import F64 as _F
from engine.ragdoll.mjcf import PropSpec, RagdollSpec

__all__ = ["RagdollSlot", "PropSlot"]


@dataclass
class RagdollSlot:
    """One ragdoll: how to build it (its command and membership are rows of the command columns)."""

    spec: RagdollSpec
    kind: bytes  # which pool slots fit it (:func:`engine.ragdoll._pool.kind_of`)
    joints: int  # its skeleton's joint count


@dataclass
class PropSlot:
    """One prop: how to build it, its starting state until built, and its MuJoCo addresses."""

    spec: PropSpec
    init: tuple[_F, _F, _F] | None = None
    qadr: int = -1
    dadr: int = -1
    geom: int = -1
    body: int = -1
