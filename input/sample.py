"""What crosses the input boundary: pose samples, per-step input frames, source status.

A :class:`PoseSample` is one reading of one controller, already in engine units
(metres, Y up, quaternions ``(w,x,y,z)``) but *not* yet calibrated or turned into a
stick: that happens in the simulation (``input/motionstick.py``) so that a replay
reproduces it. An :class:`InputFrame` is everything the hub drained for one fixed
step; it is the only non-deterministic thing the simulation reads, and exactly
what a recording stores (DESIGN: input is the one non-deterministic boundary).

Two position modes exist because controllers differ in what they know:

- ``"world"``: the sample's ``position`` is the stick's pivot in world space and
  its orientation points the stick (the mouse: a stick held at the camera eye).
- ``"device"``: orientation (and, for 6-DoF phones, ``position``) are in the
  device's own tracking space; the MotionStick applies the calibration yaw and
  puts the pivot at a virtual phone position.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field

import numpy as np

from engine.arrays import F64 as F

__all__ = [
    "PoseSample",
    "InputFrame",
    "SourceStatus",
    "CONNECT",
    "DISCONNECT",
    "TOUCH_DOWN",
    "TOUCH_UP",
    "EVENT_KINDS",
    "RESET",
    "SAVE",
    "RESTORE",
    "COMMANDS",
    "TOOL",
    "encode_tool",
    "decode_tool",
    "LIMITS",
    "check_sample_ranges",
]

CONNECT, DISCONNECT, TOUCH_DOWN, TOUCH_UP = "connect", "disconnect", "touch_down", "touch_up"
# Commands from the keyboard (the launcher's keys), recorded like any input so a
# replay resets, saves and restores where the player did.
RESET, SAVE, RESTORE = "reset", "save", "restore"
COMMANDS: tuple[str, ...] = (RESET, SAVE, RESTORE)
# An authoring tool's operation (press, drag, key …) as a short text: the authoring
# scenes take their pointer and keys through the hub so their sessions record too.
TOOL = "tool"
# Recordings store the index: new kinds go at the end.
EVENT_KINDS: tuple[str, ...] = (CONNECT, DISCONNECT, TOUCH_DOWN, TOUCH_UP, *COMMANDS, TOOL)


def encode_tool(operation: tuple[str | int | float | bool, ...]) -> str:
    """A tool operation as the compact JSON text an event carries (at most 255 bytes)."""
    text = json.dumps(list(operation), separators=(",", ":"))
    if len(text.encode()) > 255:
        raise ValueError(f"tool operation too long to record: {text[:40]}…")
    return text


def decode_tool(text: str) -> tuple[str | int | float | bool, ...]:
    """The inverse of :func:`encode_tool`: a name, then finite numbers, booleans or names."""
    try:
        operation = json.loads(text)
    except ValueError:
        raise ValueError(f"malformed tool operation {text[:40]!r}") from None
    if (
        not isinstance(operation, list)
        or not operation
        or not isinstance(operation[0], str)
        or not all(isinstance(v, (str, bool)) or (isinstance(v, (int, float)) and math.isfinite(v)) for v in operation)
    ):
        raise ValueError(f"malformed tool operation {text[:40]!r}")
    return tuple(operation)


# Physical bounds of a sample (largest magnitude per component). A finite value can still
# poison the simulation: 1e308 as a position makes the stick's velocity filter overflow to
# NaN. Real controllers stay far inside these: phones and IMUs saturate near 35 rad/s
# (2000 deg/s) and 16 g; positions are metres from the tracking origin or the camera.
LIMITS: dict[str, float] = {
    "position": 1000.0,  # m: a room, a stage, a field
    "angular_velocity": 200.0,  # rad/s
    "acceleration": 2000.0,  # m/s², about 200 g
    "plane_normal": 1.0 + 1e-6,  # a direction
    "depth_delta": 100.0,  # m per sample (a mouse wheel notch moves centimetres)
}
UNIT_NORM_TOLERANCE = 1e-3


def _vec(v: object, n: int, name: str) -> F | None:
    if v is None:
        return None
    a = np.array(v, dtype=np.float64).reshape(-1)
    if a.shape != (n,):
        raise ValueError(f"{name} needs {n} values, got {a.shape[0]}")
    return a


def check_sample_ranges(s: PoseSample) -> None:
    """Raise ``ValueError`` unless every value of ``s`` is finite and within :data:`LIMITS`.

    The one range check of the input boundary: :class:`PoseSample` runs it on construction
    and :func:`input.codec.decode_frame` on recorded samples (which bypass construction to
    keep their bits), so neither a live device nor a recording can put NaN or an absurd
    value into the world.
    """
    q = s.orientation
    n = float(np.linalg.norm(q)) if np.all(np.isfinite(q)) and np.max(np.abs(q)) <= 2.0 else float("nan")
    if not abs(n - 1.0) <= UNIT_NORM_TOLERANCE:
        raise ValueError(f"orientation is not a unit quaternion (norm {n:.4g})")
    for name in ("position", "angular_velocity", "acceleration", "plane_normal"):
        v = getattr(s, name)
        if v is None:
            continue
        if not np.all(np.isfinite(v)):
            raise ValueError(f"{name} is not finite: {v.tolist()}")
        if float(np.max(np.abs(v))) > LIMITS[name]:
            raise ValueError(f"{name} {v.tolist()} is out of range (limit {LIMITS[name]:g} per component)")
    if not (np.isfinite(s.depth_delta) and np.isfinite(s.time)):
        raise ValueError("time and depth_delta must be finite")
    if abs(s.depth_delta) > LIMITS["depth_delta"]:
        raise ValueError(f"depth_delta {s.depth_delta:g} is out of range (limit {LIMITS['depth_delta']:g})")


@dataclass(eq=False)
class PoseSample:
    """One controller reading.

    Args:
        time: seconds on the source's clock when it was received (informative only:
            the simulation steps on its own fixed clock).
        source: id of the sending controller (``"osc:127.0.0.1:5000"``, ``"mouse"``).
        orientation: unit quaternion (w,x,y,z); for ``"device"`` samples the stick
            points along the rotated +Z axis once calibrated.
        position: pivot (``"world"``) or tracked device position (``"device"``), or ``None``.
        angular_velocity: rad/s in the device frame, if the device reports it.
        acceleration: m/s² in the device frame, if the device reports it.
        touch: ``True`` pressed, ``False`` released, ``None`` unknown/unchanged.
        mode: ``"world"`` or ``"device"`` (see the module docs).
        plane_normal: keep the grab depth along this axis while held (mouse dragging
            in the plane at the grab depth); ``None`` keeps the stick length.
        depth_delta: metres to add to the grab depth (mouse wheel).
        flick: the source itself saw a flick gesture (mouse); phones flick by velocity.
        calibrate: "this is forward now" (tap-to-calibrate, a calibrate message).

    Raises:
        ValueError: on wrong sizes, non-finite or out-of-range values (:data:`LIMITS`) or a
            non-unit quaternion.
    """

    time: float
    source: str
    orientation: F
    position: F | None = None
    angular_velocity: F | None = None
    acceleration: F | None = None
    touch: bool | None = None
    mode: str = "device"
    plane_normal: F | None = None
    depth_delta: float = 0.0
    flick: bool = False
    calibrate: bool = False

    def __post_init__(self) -> None:
        q = _vec(self.orientation, 4, "orientation")
        assert q is not None
        self.orientation = q
        self.position = _vec(self.position, 3, "position")
        self.angular_velocity = _vec(self.angular_velocity, 3, "angular_velocity")
        self.acceleration = _vec(self.acceleration, 3, "acceleration")
        self.plane_normal = _vec(self.plane_normal, 3, "plane_normal")
        if self.mode not in ("world", "device"):
            raise ValueError(f"mode must be 'world' or 'device', not {self.mode!r}")
        self.time = float(self.time)
        self.depth_delta = float(self.depth_delta)
        check_sample_ranges(self)
        self.orientation = q / np.linalg.norm(q)
        if not self.source or len(self.source.encode()) > 255:
            raise ValueError("source id must be 1..255 bytes")


@dataclass(eq=False)
class InputFrame:
    """Everything the hub drained for one step: samples in arrival order and events.

    ``events`` is a tuple of ``(kind, source)`` with kind one of :data:`EVENT_KINDS`.
    It is a simulation resource (``SIM_STATE``): its content is hashed, so a replay
    that fed different input would be caught at the first differing frame.
    """

    frame: int = 0
    samples: tuple[PoseSample, ...] = ()
    events: tuple[tuple[str, str], ...] = ()

    SIM_STATE = True

    def latest(self, source: str | None = None) -> PoseSample | None:
        """The last sample of ``source`` (any source if ``None``) this step."""
        for s in reversed(self.samples):
            if source is None or s.source == source:
                return s
        return None

    def samples_of(self, source: str) -> list[PoseSample]:
        """Every sample of ``source`` this step, in arrival order (a stage uses them all)."""
        return [s for s in self.samples if s.source == source]

    def tool_operations(self) -> list[tuple[str | int | float | bool, ...]]:
        """This step's authoring tool operations, decoded; ``ValueError`` names a malformed one."""
        return [decode_tool(text) for kind, text in self.events if kind == TOOL]

    def sources(self) -> list[str]:
        """Distinct source ids in this frame, in first-seen order."""
        seen: dict[str, None] = {}
        for s in self.samples:
            seen.setdefault(s.source)
        for _, src in self.events:
            seen.setdefault(src)
        return list(seen)

    def has_event(self, kind: str, source: str | None = None) -> bool:
        """Whether an event of ``kind`` (for ``source``, or any) happened this step."""
        return any(k == kind and (source is None or s == source) for k, s in self.events)


@dataclass
class SourceStatus:
    """A source's health, for the overlay and ``puppetphone devices`` (not simulation state)."""

    name: str
    connected: bool = False
    packets: int = 0
    packets_per_s: float = 0.0
    dropped: int = 0
    last_error: str = ""
    drop_reasons: dict[str, int] = field(default_factory=dict)
    locked_out: list[str] = field(default_factory=list)  # senders refused because the slots are taken
