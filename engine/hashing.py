"""``state_hash(world)``: one digest over the whole simulation state, for replays.

What is hashed: the frame number, the RNG state, every component of every entity
(in entity-id order, components by type name), and the resources that declare
``SIM_STATE = True``. Components that are only for display declare
``SIM_STATE = False`` and are skipped. An object with a ``state_bytes()`` method
(the physics world, say) supplies its own bytes.

Floats are hashed by their exact bits: a replay on the same machine and library
versions must agree to the last bit, and a hash that rounded would hide the
first divergence until it grew visible.
"""

from __future__ import annotations

import dataclasses
import enum
import hashlib
import struct
from typing import Any

import numpy as np

from engine.ecs import World

__all__ = ["state_hash", "feed"]


def feed(h: Any, value: Any) -> None:
    """Feed a value's exact state into a hashlib object, recursively."""
    if value is None:
        h.update(b"N")
    elif isinstance(value, bool):
        h.update(b"T" if value else b"F")
    elif isinstance(value, enum.Enum):
        h.update(b"E" + str(value.value).encode())
    elif isinstance(value, int):
        h.update(b"i" + str(value).encode())
    elif isinstance(value, float):
        h.update(b"f" + struct.pack("<d", value))
    elif isinstance(value, str):
        h.update(b"s" + value.encode() + b"\0")
    elif isinstance(value, bytes):
        h.update(b"b" + struct.pack("<q", len(value)) + value)
    elif isinstance(value, np.ndarray):
        arr = np.ascontiguousarray(value)
        h.update(b"a" + arr.dtype.str.encode() + str(arr.shape).encode() + arr.tobytes())
    elif isinstance(value, np.generic):
        feed(h, value.item())
    elif hasattr(value, "state_bytes"):
        h.update(b"S" + value.state_bytes())
    elif dataclasses.is_dataclass(value) and not isinstance(value, type):
        h.update(b"D" + type(value).__qualname__.encode())
        for f in dataclasses.fields(value):
            if f.metadata.get("hash", True):
                feed(h, getattr(value, f.name))
    elif isinstance(value, (list, tuple)):
        h.update(b"L" + str(len(value)).encode())
        for v in value:
            feed(h, v)
    elif isinstance(value, dict):
        h.update(b"M" + str(len(value)).encode())
        for k in sorted(value, key=repr):
            feed(h, k)
            feed(h, value[k])
    elif isinstance(value, (set, frozenset)):
        h.update(b"Z")
        for v in sorted(value, key=repr):
            feed(h, v)
    else:
        raise TypeError(f"cannot hash {type(value).__name__}: make it a dataclass or give it state_bytes()")


def state_hash(world: World) -> str:
    """Hex digest (BLAKE2b, 16 bytes) of the world's simulation state."""
    h = hashlib.blake2b(digest_size=16)
    feed(h, world.frame)
    feed(h, world.rng.bit_generator.state)
    for e in world.entities():
        feed(h, e)
        for comp in world.components_of(e):
            if getattr(comp, "SIM_STATE", True):
                feed(h, comp)
    for res in world.resources():
        if getattr(res, "SIM_STATE", False):
            feed(h, res)
    return h.hexdigest()
