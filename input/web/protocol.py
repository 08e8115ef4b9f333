"""The web controller's messages: one JSON text frame per sensor reading, checked here only.

This is the one validation boundary of the web format: whatever the page (or anyone
holding the session link) sends passes :func:`parse_message`, which either returns a
:class:`ControllerMessage` or raises :class:`WebMessageError` with a one-line reason
the server counts and drops. Nothing else in the engine sees the raw JSON.

A reading (the page sends one per sensor event, at the sensor's rate)::

    {"seq": 17, "t": 1732400000123.4, "kind": "orientation",
     "o": [alpha, beta, gamma],            # deviceorientation, degrees
     "acc": [x, y, z], "rot": [a, b, g],   # devicemotion: m/s², deg/s (optional)
     "touch": true, "jump": false, "cal": false, "crouch": 0.0}

or, in WebXR ``immersive-ar``, ``"kind": "xr"`` with ``"q": [x, y, z, w]`` and
``"p": [x, y, z]`` (the viewer's pose in the ``local`` reference space: metres, Y up,
looking along -Z). ``t`` is the page's clock (``performance.timeOrigin + now()``,
milliseconds since the epoch) when the sensor event fired: it is used for latency
figures only, never by the simulation. ``{"ping": t}`` asks for ``{"pong": t}``.
``{"ack": step}`` says the page has received the scene frame of that step (the
server's back-pressure, :mod:`input.web.server`); it never reaches the simulation.

Conversion (:func:`to_sample_fields`): DeviceOrientation angles are the intrinsic
Z-X'-Y'' rotation of the W3C spec, device → Earth (X east, Y north, Z up), so the
attitude is ``Rz(alpha)·Rx(beta)·Ry(gamma)`` and :func:`input.phone_frames.phone_to_stick`
makes it a stick (out of the phone's top edge). A WebXR viewer is oriented like an
ARKit camera (:func:`input.phone_frames.arkit_to_stick`). The crouch slider lowers the
stick's pivot by up to :data:`CROUCH_DEPTH` metres, as lowering the phone would (the
page moves it at 1.5 of its range per second at most, so raising the slider is never as
fast as a flick); the jump button is a flick.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from engine import quat
from engine.arrays import F64 as F
from engine.errors import FormatError
from input.phone_frames import arkit_to_stick, phone_to_stick

__all__ = [
    "ControllerMessage",
    "Ping",
    "Ack",
    "WebMessageError",
    "parse_message",
    "to_sample_fields",
    "orientation_to_quat",
    "MAX_MESSAGE_BYTES",
    "CROUCH_DEPTH",
    "KINDS",
    "PageClock",
]

#: A reading is about 200 bytes; anything much longer is not from the page.
MAX_MESSAGE_BYTES = 1024
#: Metres the stick's pivot goes down with the crouch slider at its end (stand 0.95 m → crouch 0.55 m).
CROUCH_DEPTH = 0.45
KINDS = ("orientation", "xr")
_KEYS = {"seq", "t", "kind", "o", "q", "p", "acc", "rot", "touch", "jump", "cal", "crouch"}
_DEG = math.pi / 180.0


class WebMessageError(FormatError):
    """A message from a controller page that is not a valid reading (the reason, one line)."""


@dataclass(frozen=True)
class Ping:
    """A page measuring its round trip: echo ``t`` back."""

    t: float


@dataclass(frozen=True)
class Ack:
    """The page has the scene frame of ``step``: the server may send it another."""

    step: int


@dataclass(frozen=True)
class ControllerMessage:
    """One validated reading from the controller page (see the module docstring)."""

    seq: int
    t: float
    kind: str
    orientation: F  # stick orientation (w,x,y,z), engine axes
    position: F | None
    acceleration: F | None
    angular_velocity: F | None
    touch: bool
    jump: bool
    calibrate: bool
    crouch: float


def _number(v: Any, name: str, limit: float) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise WebMessageError(f"{name} must be a number")
    f = float(v)
    if not math.isfinite(f) or abs(f) > limit:
        raise WebMessageError(f"{name} is out of range")
    return f


def _vector(v: Any, n: int, name: str, limit: float) -> F:
    if not isinstance(v, list) or len(v) != n:
        raise WebMessageError(f"{name} must be a list of {n} numbers")
    return np.array([_number(x, name, limit) for x in v], dtype=np.float64)


def _flag(v: Any, name: str) -> bool:
    if v is None:
        return False
    if not isinstance(v, bool):
        raise WebMessageError(f"{name} must be true or false")
    return v


def orientation_to_quat(alpha: float, beta: float, gamma: float) -> F:
    """Device → Earth (Z up) attitude of DeviceOrientation angles in degrees (W3C: Z-X'-Y'')."""
    rz = quat.from_axis_angle([0.0, 0.0, 1.0], alpha * _DEG)
    rx = quat.from_axis_angle([1.0, 0.0, 0.0], beta * _DEG)
    ry = quat.from_axis_angle([0.0, 1.0, 0.0], gamma * _DEG)
    return quat.normalize(quat.mul(quat.mul(rz, rx), ry))


def parse_message(text: str | bytes) -> ControllerMessage | Ping | Ack:
    """Check one WebSocket message from the page.

    Raises:
        WebMessageError: binary, too long, not JSON, unknown keys, wrong types, values out of range.
    """
    if not isinstance(text, str):
        raise WebMessageError("binary message")
    if len(text) > MAX_MESSAGE_BYTES:
        raise WebMessageError("message too long")
    try:
        msg = json.loads(text)
    except (ValueError, RecursionError):
        raise WebMessageError("not JSON") from None
    if not isinstance(msg, dict):
        raise WebMessageError("not a JSON object")
    if set(msg) == {"ping"}:
        return Ping(_number(msg["ping"], "ping", 1e16))
    if set(msg) == {"ack"}:
        step = msg["ack"]
        if isinstance(step, bool) or not isinstance(step, int) or not 0 <= step < 2**32:
            raise WebMessageError("ack must be a step number")
        return Ack(step)
    unknown = set(msg) - _KEYS
    if unknown:
        raise WebMessageError(f"unknown field {min(unknown)[:20]!r}")
    seq = msg.get("seq")
    if isinstance(seq, bool) or not isinstance(seq, int) or not 0 <= seq < 2**53:
        raise WebMessageError("seq must be a whole number")
    t = _number(msg.get("t"), "t", 1e16)
    kind = msg.get("kind")
    if kind not in KINDS:
        raise WebMessageError(f"kind must be one of {', '.join(KINDS)}")
    position = None
    if kind == "orientation":
        alpha, beta, gamma = _vector(msg.get("o"), 3, "o", 360.0)
        orientation = phone_to_stick(orientation_to_quat(alpha, beta, gamma))
    else:
        q = _vector(msg.get("q"), 4, "q", 1.01)
        n = float(np.linalg.norm(q))
        if abs(n - 1.0) > 1e-3:
            raise WebMessageError("q is not a unit quaternion")
        orientation = arkit_to_stick(quat.from_xyzw(q / n))
        position = _vector(msg.get("p"), 3, "p", 1000.0)
    acc = None if msg.get("acc") is None else _vector(msg["acc"], 3, "acc", 2000.0)
    rot = None if msg.get("rot") is None else _vector(msg["rot"], 3, "rot", 11000.0)
    crouch = 0.0 if msg.get("crouch") is None else _number(msg["crouch"], "crouch", 1.0)
    if crouch < 0.0:
        raise WebMessageError("crouch is out of range")
    # rotationRate is (alpha, beta, gamma) = about device (z, x, y), deg/s.
    angular = None if rot is None else np.array([rot[1], rot[2], rot[0]]) * _DEG
    return ControllerMessage(
        seq=seq,
        t=t,
        kind=kind,
        orientation=orientation,
        position=position,
        acceleration=acc,
        angular_velocity=angular,
        touch=_flag(msg.get("touch"), "touch"),
        jump=_flag(msg.get("jump"), "jump"),
        calibrate=_flag(msg.get("cal"), "cal"),
        crouch=crouch,
    )


def to_sample_fields(msg: ControllerMessage, source: str, received: float) -> dict[str, Any]:
    """The :class:`input.sample.PoseSample` fields of a reading, stamped ``received`` (the server's
    clock at the sensor event: :class:`PageClock` maps the page's ``t`` onto it)."""
    position = np.zeros(3) if msg.position is None else msg.position.copy()
    position[1] -= CROUCH_DEPTH * msg.crouch
    return {
        "time": received,
        "source": source,
        "orientation": msg.orientation,
        "position": position,
        "angular_velocity": msg.angular_velocity,
        "acceleration": msg.acceleration,
        "touch": msg.touch,
        "mode": "device",
        "flick": msg.jump,
        "calibrate": msg.calibrate,
    }


class PageClock:
    """The page's event times (``t``, ms since the epoch on the phone) on the server's clock.

    Readings travel in bursts over Wi-Fi, so their arrival times bunch up and a velocity
    taken between arrivals is noise; the sensor events' own spacing is right. The offset
    between the two clocks is the smallest seen ``arrival − t`` (the least-delayed reading),
    so a stamp is never later than its arrival; a page clock that jumps back or runs far
    ahead (a phone setting its clock) restarts the estimate.
    """

    def __init__(self) -> None:
        self.offset: float | None = None

    def stamp(self, page_ms: float, arrival: float) -> float:
        """The server-clock time of a reading whose page time is ``page_ms``, received at ``arrival``."""
        seen = arrival - page_ms / 1000.0
        if self.offset is None or seen < self.offset or seen > self.offset + 1.0:
            self.offset = seen
        return min(page_ms / 1000.0 + self.offset, arrival)
