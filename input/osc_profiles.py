"""OSC address profiles: our own scheme and real phone apps, decoded into pose samples.

:class:`OscDecoder` is pure (no sockets): it takes one datagram and its sender and
returns at most one :class:`PoseSample` for that sender, so bundles (ZIG SIM sends
one per tick) become one sample, and single messages (Sensors2OSC) one each. Every
rejected packet or message is reported through ``on_drop(reason, detail)``; nothing
raises. A packet whose values are finite but out of a sample's range (``input.sample.LIMITS``)
is dropped whole and leaves its sender's state as it was before the packet. Profiles are detected from the address (input-protocols §1):

==================  ===========================================================
our scheme          ``/puppetphone/pose x y z qw qx qy qz`` (engine axes, Y up),
                    ``/puppetphone/orientation qw qx qy qz``, ``/puppetphone/touch i``,
                    ``/puppetphone/calibrate``, ``/puppetphone/gyro``, ``/puppetphone/accel``
ZIG SIM             ``…/quaternion`` x,y,z,w; ``…/arkitposition`` + ``…/arkitrotation``
                    (x,y,z,w) for 6-DoF; ``…/touch<ID><1|2>``; ``…/gyro`` rad/s; ``…/accel`` g
Sensors2OSC         ``/rotationvector`` (and ``game``/``geo``) x,y,z,w[,acc]; ``/pose6dof``;
                    ``/touch1`` x y (−1,−1 = lifted); ``/gyroscope``; ``/accelerometer``
TouchOSC Mk1        ``/accxyz`` x,y,z in g: tilt only
GyrOSC              ``/gyrosc/quat`` (order configurable, default w,x,y,z),
                    ``/gyrosc/gyro`` pitch,roll,yaw rad, ``/gyrosc/rrate``, ``/gyrosc/accel``,
                    ``/gyrosc/button``
==================  ===========================================================
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
import pythonosc
from pythonosc import osc_packet
from pythonosc.dispatcher import Dispatcher

from engine import quat
from input.phone_frames import arkit_to_stick, phone_to_stick, reorder_quat, tilt_from_gravity, z_up_to_engine
from input.sample import PoseSample

__all__ = ["OscDecoder", "SenderState", "G"]

from engine.arrays import F64 as F

G = 9.80665
UNIT_TOLERANCE = 0.05  # phones send float32 quaternions; beyond this the packet is wrong
# No phone app sends a number this large (metres, rad/s, m/s², g); a bigger one is an attack or
# garbage, and rejecting it here keeps scaling arithmetic (g to m/s²) from overflowing.
MAX_ARGUMENT = 1e6


class Reject(Exception):
    """One message is invalid; the reason is its text."""


@dataclass
class SenderState:
    """What one sender has told us so far (samples always carry a full pose)."""

    orientation: F = field(default_factory=lambda: phone_to_stick(quat.identity()))
    position: F | None = None
    gyro: F | None = None
    accel: F | None = None
    touch: bool | None = None
    calibrate: bool = False
    dirty: bool = False
    touch_in_packet: bool = False
    uses_packet_touch: bool = False
    arkit_rotation: bool = False


def _floats(args: tuple[Any, ...], n: int, n_max: int | None = None) -> F:
    n_max = n if n_max is None else n_max
    if not n <= len(args) <= n_max:
        want = str(n) if n == n_max else f"{n}..{n_max}"
        raise Reject(f"wrong arity: {len(args)} arguments, expected {want}")
    for a in args:
        if isinstance(a, bool) or not isinstance(a, (int, float)):
            raise Reject(f"wrong type: {type(a).__name__} argument")
    v = np.array(args, dtype=np.float64)
    if not np.all(np.isfinite(v)):
        raise Reject("non-finite value")
    if np.max(np.abs(v), initial=0.0) > MAX_ARGUMENT:
        raise Reject(f"value out of range (beyond {MAX_ARGUMENT:g})")
    return v


def _unit(q: F) -> F:
    n = float(np.linalg.norm(q))
    if abs(n - 1.0) > UNIT_TOLERANCE:
        raise Reject(f"non-unit quaternion (norm {n:.3g})")
    return q / n


class _PythonOscWarnings(logging.Filter):
    """Drops python-osc's per-packet ``logging.warning`` lines (an unknown type tag, an unknown
    bundle element): under garbage they printed a line per packet, 1,413 of them in one test.
    The decoder counts what it drops in the source's status instead."""

    def filter(self, record: logging.LogRecord) -> bool:
        return not record.pathname.startswith(_PYTHONOSC_DIR)


_PYTHONOSC_DIR = str(Path(pythonosc.__file__).resolve().parent)


def _quiet_python_osc() -> None:
    """Install the filter on the root logger python-osc logs to (once; idempotent)."""
    root = logging.getLogger()
    if not any(isinstance(f, _PythonOscWarnings) for f in root.filters):
        root.addFilter(_PythonOscWarnings())


class OscDecoder:
    """Turns OSC datagrams into pose samples, one sender state per sender.

    Args:
        on_drop: called with ``(reason, detail)`` for every rejected packet/message.
        gyrosc_order: GyrOSC's quaternion order (unconfirmed upstream, so configurable).
        accxyz_up_sign: sign that turns TouchOSC's ``/accxyz`` into an "up" vector
            (iOS reports −1 g on Z lying flat, hence −1).
    """

    def __init__(
        self, on_drop: Callable[[str, str], None], gyrosc_order: str = "wxyz", accxyz_up_sign: float = -1.0
    ) -> None:
        reorder_quat(np.zeros(4), gyrosc_order)  # validates the order early
        _quiet_python_osc()
        self.on_drop = on_drop
        self.gyrosc_order = gyrosc_order
        self.accxyz_up_sign = accxyz_up_sign
        self.senders: dict[str, SenderState] = {}
        self._state = SenderState()
        d = Dispatcher(strict_timing=False)
        for address, handler in (
            ("/puppetphone/pose", self._pp_pose),
            ("/puppetphone/orientation", self._pp_orientation),
            ("/puppetphone/touch", self._pp_touch),
            ("/puppetphone/calibrate", self._pp_calibrate),
            ("/puppetphone/gyro", self._gyro_rad),
            ("/puppetphone/accel", self._accel_ms2),
            # ZIG SIM: "/ZIGSIM/<uuid>/name" in its source, "/<uuid>/name" in its docs: match both.
            ("/*/quaternion", self._zig_quaternion),
            ("/*/arkitposition", self._zig_arkit_position),
            ("/*/arkitrotation", self._zig_arkit_rotation),
            ("/*/touch[0-9]*", self._zig_touch),
            ("/*/touchradius*", self._zig_touch),
            ("/*/touchforce*", self._zig_touch),
            ("/ZIGSIM/*/gyro", self._gyro_rad),
            ("/ZIGSIM/*/accel", self._accel_g),
            ("/*/deviceinfo", self._ignore),
            ("/ZIGSIM/*/gravity", self._ignore),
            ("/rotationvector", self._s2o_rotation),
            ("/gamerotationvector", self._s2o_rotation),
            ("/georotationvector", self._s2o_rotation),
            ("/pose6dof", self._s2o_pose6dof),
            ("/touch1", self._s2o_touch),
            ("/gyroscope", self._gyro_rad),
            ("/accelerometer", self._accel_ms2),
            ("/accxyz", self._touchosc_accxyz),
            ("/gyrosc/quat", self._gyrosc_quat),
            ("/gyrosc/gyro", self._gyrosc_euler),
            ("/gyrosc/rrate", self._gyro_rad),
            ("/gyrosc/accel", self._accel_g),
            ("/gyrosc/button", self._gyrosc_button),
        ):
            d.map(address, handler)
        self.dispatcher = d

    def decode(self, data: bytes, sender: str, now: float) -> PoseSample | None:
        """The sample this datagram from ``sender`` yields, or ``None`` (nothing new or rejected)."""
        try:
            messages = osc_packet.OscPacket(data).messages
        except Exception as exc:  # python-osc raises ParseError, and a few others on garbage
            self.on_drop("malformed packet", f"{type(exc).__name__}: {exc}"[:200])
            return None
        st = self.senders.get(sender)
        fresh = st is None
        before = None if st is None else replace(st)
        self._state = st = SenderState() if st is None else st
        st.touch_in_packet = False
        for timed in messages:
            msg = timed.message
            if any(c in msg.address for c in "*?[]{}"):
                # A pattern would fan out to every matching handler; no phone app sends one.
                self.on_drop("address pattern", msg.address[:100])
                continue
            handlers = list(self.dispatcher.handlers_for_address(msg.address))
            if not handlers:
                self.on_drop("unknown address", msg.address[:100])
                continue
            try:
                handlers[0].callback(msg.address, *msg.params)
            except Reject as exc:
                self.on_drop(str(exc).split(":")[0].split(" (")[0], f"{msg.address}: {exc}")
        if st.uses_packet_touch and st.touch is not st.touch_in_packet:
            st.touch, st.dirty = st.touch_in_packet, True
        if not st.dirty:
            return None
        st.dirty = False
        cal, st.calibrate = st.calibrate, False
        try:
            sample = PoseSample(
                time=now,
                source=sender,
                orientation=st.orientation,
                position=st.position,
                angular_velocity=st.gyro,
                acceleration=st.accel,
                touch=st.touch,
                calibrate=cal,
            )
        except ValueError as exc:  # finite but out of range (a 1e308 position): forget the whole packet
            if before is not None:
                self.senders[sender] = before
            self.on_drop("invalid sample", f"{sender}: {exc}"[:200])
            return None
        if fresh:
            self.senders[sender] = st
        return sample

    # -- shared handlers ----------------------------------------------------------------
    def _set_orientation(self, o: F) -> None:
        self._state.orientation, self._state.dirty = o, True

    def _ignore(self, address: str, *args: Any) -> None:
        return None

    def _gyro_rad(self, address: str, *args: Any) -> None:
        self._state.gyro, self._state.dirty = _floats(args, 3), True

    def _accel_ms2(self, address: str, *args: Any) -> None:
        self._state.accel, self._state.dirty = _floats(args, 3), True

    def _accel_g(self, address: str, *args: Any) -> None:
        self._state.accel, self._state.dirty = _floats(args, 3) * G, True

    def _touch(self, down: bool) -> None:
        if self._state.touch is not down:
            self._state.touch, self._state.dirty = down, True

    # -- our own scheme -------------------------------------------------------------------
    def _pp_pose(self, address: str, *args: Any) -> None:
        v = _floats(args, 7)
        q = _unit(v[3:])
        self._state.position = v[:3]
        self._set_orientation(q)

    def _pp_orientation(self, address: str, *args: Any) -> None:
        self._set_orientation(_unit(_floats(args, 4)))

    def _pp_touch(self, address: str, *args: Any) -> None:
        self._touch(bool(_floats(args, 1)[0]))

    def _pp_calibrate(self, address: str, *args: Any) -> None:
        self._state.calibrate = self._state.dirty = True

    # -- ZIG SIM ---------------------------------------------------------------------------
    def _zig_quaternion(self, address: str, *args: Any) -> None:
        q = _unit(reorder_quat(_floats(args, 4), "xyzw"))
        if not self._state.arkit_rotation:  # ARKit's attitude matches its position: prefer it
            self._set_orientation(phone_to_stick(q))

    def _zig_arkit_position(self, address: str, *args: Any) -> None:
        self._state.position, self._state.dirty = _floats(args, 3), True

    def _zig_arkit_rotation(self, address: str, *args: Any) -> None:
        q = _unit(reorder_quat(_floats(args, 4), "xyzw"))
        self._state.arkit_rotation = True
        self._set_orientation(arkit_to_stick(q))

    def _zig_touch(self, address: str, *args: Any) -> None:
        _floats(args, 1, 2)
        self._state.uses_packet_touch = True  # ZIG SIM: a finger is down while touch messages come
        self._state.touch_in_packet = True

    # -- Sensors2OSC ------------------------------------------------------------------------
    def _s2o_rotation(self, address: str, *args: Any) -> None:
        v = _floats(args, 3, 5)
        if len(v) == 3:  # pre-API-18 devices omit w: it is implied by the unit norm
            v = np.append(v, math.sqrt(max(0.0, 1.0 - float(v @ v))))
        self._set_orientation(phone_to_stick(_unit(reorder_quat(v[:4], "xyzw"))))

    def _s2o_pose6dof(self, address: str, *args: Any) -> None:
        v = _floats(args, 7, 15)
        self._state.position = z_up_to_engine(v[4:7])
        self._set_orientation(phone_to_stick(_unit(reorder_quat(v[:4], "xyzw"))))

    def _s2o_touch(self, address: str, *args: Any) -> None:
        x, y = _floats(args, 2)
        self._touch(not (x < 0 and y < 0))

    # -- TouchOSC Mk1 -----------------------------------------------------------------------
    def _touchosc_accxyz(self, address: str, *args: Any) -> None:
        a = _floats(args, 3)
        self._state.accel = a * G
        self._set_orientation(phone_to_stick(tilt_from_gravity(self.accxyz_up_sign * a)))

    # -- GyrOSC ------------------------------------------------------------------------------
    def _gyrosc_quat(self, address: str, *args: Any) -> None:
        self._set_orientation(phone_to_stick(_unit(reorder_quat(_floats(args, 4), self.gyrosc_order))))

    def _gyrosc_euler(self, address: str, *args: Any) -> None:
        pitch, roll, yaw = _floats(args, 3)
        q = quat.from_euler("zxy", [yaw, pitch, roll])  # heading about Z-up, then pitch, then roll
        self._set_orientation(phone_to_stick(q))

    def _gyrosc_button(self, address: str, *args: Any) -> None:
        v = _floats(args, 1, 2)
        self._touch(bool(v[-1]))
