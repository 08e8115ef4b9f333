"""The typed operations a hand (or a script) makes in a session, and their one decoder.

A window event becomes an operation (:mod:`authoring.bindings`), the operation travels
through the input hub as a tool event (so a recording keeps it and a replay feeds it back),
and :func:`decode` turns the recorded tuple back into one of these classes: the only place
where a recorded operation is checked. A scene then matches on the class, never on a string.

Older recordings stay readable: ``key`` without its shift flag, ``release`` without a
position and the record scene's ``pointer`` (its sampled drag position, now a ``move``).
"""

from __future__ import annotations

import math
from dataclasses import astuple, dataclass
from typing import TypeGuard

__all__ = ["OPERATIONS", "Key", "Move", "Operation", "Orbit", "Press", "Release", "Resize", "Zoom", "decode", "encode"]

Raw = tuple[str | int | float | bool, ...]


@dataclass(frozen=True)
class Press:
    """The acting button goes down at a pixel; ``shift``: the alternative action (Shift held)."""

    x: float
    y: float
    shift: bool = False


@dataclass(frozen=True)
class Move:
    """The pointer is at this pixel (one per step: the latest move of the step)."""

    x: float
    y: float


@dataclass(frozen=True)
class Release:
    """The acting button comes up (at a pixel; an old record-scene take carries none)."""

    x: float | None = None
    y: float | None = None


@dataclass(frozen=True)
class Orbit:
    """Turn the camera by a drag of ``dx, dy`` pixels (summed over the step)."""

    dx: float
    dy: float


@dataclass(frozen=True)
class Zoom:
    """Scale the camera's distance by ``factor`` (below 1: closer)."""

    factor: float


@dataclass(frozen=True)
class Key:
    """A key by pygame's name (``s``, ``tab``, ``return``…) with Ctrl and Shift."""

    name: str
    ctrl: bool = False
    shift: bool = False


@dataclass(frozen=True)
class Resize:
    """The window is now ``width × height`` pixels."""

    width: int
    height: int


Operation = Press | Move | Release | Orbit | Zoom | Key | Resize

#: Recorded name → class.
OPERATIONS: dict[str, type[Operation]] = {
    "press": Press,
    "move": Move,
    "release": Release,
    "orbit": Orbit,
    "zoom": Zoom,
    "key": Key,
    "size": Resize,
}
_NAMES = {cls: name for name, cls in OPERATIONS.items()}


def encode(op: Operation) -> Raw:
    """The tuple a tool event records (``decode`` reverses it)."""
    values = astuple(op)
    if isinstance(op, Release) and op.x is None:
        values = ()
    return (_NAMES[type(op)], *values)


def _number(v: object, what: str) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise ValueError(f"{what} is not a finite number: {v!r}")
    return float(v)


def _whole(v: object) -> TypeGuard[int]:
    """Whether ``v`` is a whole number (a JSON ``true`` is not one)."""
    return isinstance(v, int) and not isinstance(v, bool)


def _flag(v: object, what: str) -> bool:
    if not isinstance(v, bool):
        raise ValueError(f"{what} is not true or false: {v!r}")
    return v


def decode(raw: Raw | list[object]) -> Operation:
    """One recorded operation as its class; ``ValueError`` in one line for anything that is none."""
    if not raw or not isinstance(raw[0], str):
        raise ValueError(f"tool operation {list(raw)!r:.60} has no name")
    name, args = ("move" if raw[0] == "pointer" else raw[0]), list(raw[1:])
    where = f"tool operation {list(raw)!r:.60}"
    try:
        if name == "press" and len(args) in (2, 3):
            return Press(
                _number(args[0], where), _number(args[1], where), _flag(args[2], where) if len(args) == 3 else False
            )
        if name == "move" and len(args) == 2:
            return Move(_number(args[0], where), _number(args[1], where))
        if name == "release" and len(args) in (0, 2):
            return Release(*(_number(v, where) for v in args))
        if name == "orbit" and len(args) == 2:
            return Orbit(_number(args[0], where), _number(args[1], where))
        if name == "zoom" and len(args) == 1:
            factor = _number(args[0], where)
            if not 0.01 <= factor <= 100.0:
                raise ValueError(f"{where}: zoom factor out of 0.01..100")
            return Zoom(factor)
        if name == "key" and len(args) in (2, 3) and isinstance(args[0], str):
            return Key(args[0], _flag(args[1], where), _flag(args[2], where) if len(args) == 3 else False)
        if name == "size" and len(args) == 2:
            w, h = args
            if _whole(w) and _whole(h) and 0 < w <= 16384 and 0 < h <= 16384:
                return Resize(w, h)
    except ValueError as exc:
        raise ValueError(str(exc)) from None
    raise ValueError(f"{where} is not one a session knows ({', '.join(OPERATIONS)} with their arguments)")
