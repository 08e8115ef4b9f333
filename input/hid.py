"""HID controllers as pose sources: SpaceMouse (6-DoF by integration) and Sony gyros.

Device specifics are decoded by :mod:`input.hid_reports`; this module turns them
into a stick pose and owns the device thread:

- :class:`SpaceMouseIntegrator`: the cap is a velocity controller. Raw axes (X right,
  Y towards the user, Z down) map to engine axes as ``(−X, −Z, −Y)`` for a view along
  +Z; beyond a dead zone, translation moves the pivot (``speed`` m/s at full push)
  and rotation turns the stick (``turn_rate`` rad/s).
- :class:`ImuIntegrator`: gyro integrated to orientation (sensor timestamps give
  dt), and a complementary filter pulls the tilt towards the measured gravity when
  the controller is not accelerating, so pitch and roll do not drift (yaw can, and
  tap-to-calibrate resets it). Controller axes are X right, Y up, Z towards the
  player; the stick points away from the player.
- :class:`HidSource`: opens the first matching device, reads the calibration
  feature report when there is one, and on an unplug reports a disconnect (the
  stick releases its puppet) and keeps trying to reopen, so plugging back in
  reconnects by itself.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

import numpy as np

from engine import quat
from input.hid_reports import (
    DS4_DEFAULT,
    DUALSENSE_DEFAULT,
    SPACEMOUSE_COMBINED,
    HidFormatError,
    ImuCalibration,
    ImuReport,
    ds4_calibration,
    dualsense_calibration,
    known_device,
    parse_ds4,
    parse_dualsense,
    parse_spacemouse,
)
from input.phone_frames import STICK_TO_ARKIT_CAMERA
from input.sample import LIMITS
from input.source import PoseSource

__all__ = ["SpaceMouseIntegrator", "ImuIntegrator", "HidSource", "enumerate_supported"]

from engine.arrays import F64 as F

_RAW_TO_ENGINE = np.array([[-1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, -1.0, 0.0]])


class SpaceMouseIntegrator:
    """Integrates SpaceMouse velocities into a 6-DoF pose (engine axes)."""

    def __init__(self, dead_zone: float = 0.06, speed: float = 1.5, turn_rate: float = 2.0) -> None:
        self.dead_zone, self.speed, self.turn_rate = dead_zone, speed, turn_rate
        self.position = np.zeros(3)
        self.orientation = quat.identity()
        self.translation = np.zeros(3)
        self.rotation = np.zeros(3)
        self.buttons = 0

    def _dz(self, v: F) -> F:
        mag = np.abs(v)
        return np.where(mag > self.dead_zone, np.sign(v) * (mag - self.dead_zone) / (1.0 - self.dead_zone), 0.0)

    def update(self, report: bytes | list[int], dt: float) -> None:
        """Take one report and advance the pose by ``dt`` seconds at the current velocities."""
        r = parse_spacemouse(report)
        if r.translation is not None:
            self.translation = _RAW_TO_ENGINE @ self._dz(np.clip(r.translation, -1, 1))
        if r.rotation is not None:
            self.rotation = _RAW_TO_ENGINE @ self._dz(np.clip(r.rotation, -1, 1))
        if r.buttons is not None:
            self.buttons = r.buttons
        dt = min(max(dt, 0.0), 0.05)
        # Held long enough, a push would carry the pivot past what a sample may hold: stop at the edge.
        limit = LIMITS["position"]
        self.position = np.clip(self.position + self.translation * self.speed * dt, -limit, limit)
        # Turn about world axes (the cap's twist reads as "turn the stick this way").
        self.orientation = quat.normalize(quat.mul(quat.exp(self.rotation * self.turn_rate * dt), self.orientation))


class ImuIntegrator:
    """Gyro + accelerometer → orientation (complementary filter), controller axes."""

    def __init__(self, calibration: ImuCalibration, gain: float = 0.02) -> None:
        self.calibration = calibration
        self.gain = gain
        self.orientation = quat.identity()
        self.gyro = np.zeros(3)
        self.accel = np.zeros(3)
        self._last_ts: float | None = None
        self._period: float | None = None

    def update(self, r: ImuReport, wrap: float) -> None:
        """Integrate one report; ``wrap`` is the sensor timestamp's wrap-around period in seconds."""
        gyro, accel = self.calibration.apply(r.gyro, r.accel)
        # Sony gyro axes are pitch (X), yaw (Y), roll (Z): already a rotation vector in controller axes.
        self.gyro, self.accel = gyro, accel
        if self._last_ts is None:
            self._last_ts = r.timestamp
            return
        dt = (r.timestamp - self._last_ts) % wrap
        self._last_ts = r.timestamp
        dt = min(dt, 0.05)
        q = quat.mul(self.orientation, quat.exp(gyro * dt))
        g = float(np.linalg.norm(accel))
        if 0.8 < g < 1.2:  # only trust gravity when the controller is not being swung
            up_world = quat.rotate(q, accel / g)
            corr = quat.between(up_world, [0.0, 1.0, 0.0])
            q = quat.mul(quat.slerp(quat.identity(), corr, self.gain), q)
        self.orientation = quat.normalize(q)

    def stick_orientation(self) -> F:
        """Stick orientation: pointing away from the player (controller −Z)."""
        return quat.normalize(quat.mul(self.orientation, STICK_TO_ARKIT_CAMERA))


def enumerate_supported(enumerate_fn: Callable[[], list[dict[str, Any]]] | None = None) -> list[dict[str, Any]]:
    """hidapi's device list filtered to supported devices, each with ``kind`` and ``name`` added."""
    if enumerate_fn is None:
        try:
            import hid
        except ImportError:
            return []
        enumerate_fn = hid.enumerate
    out = []
    for d in enumerate_fn():
        k = known_device(d.get("vendor_id", 0), d.get("product_id", 0))
        if k is not None:
            out.append({**d, "kind": k[0], "name": k[1]})
    return out


class HidSource(PoseSource):
    """Reads one HID controller (the first supported one, or the given VID:PID).

    Args:
        vid, pid: a specific device; ``None`` takes the first supported one found.
        retry: seconds between attempts to (re)open.
        opener: ``() -> device`` with hidapi's ``read``/``get_feature_report``/``close``
            (tests pass a fake; default opens through hidapi).
    """

    def __init__(
        self,
        vid: int | None = None,
        pid: int | None = None,
        retry: float = 1.0,
        opener: Callable[[], Any] | None = None,
        capacity: int = 256,
    ) -> None:
        super().__init__("hid", capacity)
        self.vid, self.pid, self.retry = vid, pid, retry
        self._opener = opener
        self.kind = ""
        self.source_id = "hid"

    def _open(self) -> Any | None:
        if self._opener is not None:
            return self._opener()
        import hid

        for d in enumerate_supported():
            if self.vid is not None and (d["vendor_id"], d["product_id"]) != (self.vid, self.pid):
                continue
            dev = hid.device()
            dev.open_path(d["path"])
            self.vid, self.pid = d["vendor_id"], d["product_id"]
            return dev
        return None

    def _run(self) -> None:
        while not self.stopping.is_set():
            try:
                dev = self._open()
            except (OSError, ValueError) as exc:
                self.error(f"cannot open HID device: {exc}")
                dev = None
            if dev is None:
                self.stopping.wait(self.retry)
                continue
            k = known_device(self.vid or 0, self.pid or 0)
            self.kind = k[0] if k else "spacemouse"
            self.source_id = f"hid:{self.vid or 0:04x}:{self.pid or 0:04x}"
            self.connected(self.source_id)
            try:
                self._read_loop(dev)
            except (OSError, ValueError) as exc:
                self.error(f"HID device lost: {exc}")
            finally:
                try:
                    dev.close()
                except (OSError, ValueError):
                    pass
            self.disconnected(self.source_id)
            self.stopping.wait(self.retry)

    def _calibration(self, dev: Any) -> ImuCalibration:
        try:
            if self.kind == "ds4":
                return ds4_calibration(dev.get_feature_report(0x02, 37))
            return dualsense_calibration(dev.get_feature_report(0x05, 41))
        except (OSError, ValueError, HidFormatError) as exc:
            self.error(f"no usable calibration report ({exc}); using default scales")
            return DS4_DEFAULT if self.kind == "ds4" else DUALSENSE_DEFAULT

    def _read_loop(self, dev: Any) -> None:
        if self.kind == "spacemouse":
            sm = SpaceMouseIntegrator()
            last = time.monotonic()
            combined = (self.vid, self.pid) in SPACEMOUSE_COMBINED
            while not self.stopping.is_set():
                data = dev.read(64, 50)
                now = time.monotonic()
                if not data:
                    continue  # the cap at rest sends nothing: no motion to integrate
                try:
                    sm.update(bytes(data), now - last)
                except HidFormatError as exc:
                    self.drop("bad report", str(exc))
                    continue
                last = now
                if data[0] == 1 or not combined:
                    self.offer(
                        time=now,
                        source=self.source_id,
                        orientation=sm.orientation,
                        position=sm.position,
                        touch=bool(sm.buttons & 1),
                    )
            return
        imu = ImuIntegrator(self._calibration(dev))
        parse, wrap = (parse_ds4, 65536 * 16 / 3 * 1e-6) if self.kind == "ds4" else (parse_dualsense, 2**32 / 3 * 1e-6)
        while not self.stopping.is_set():
            data = dev.read(78, 50)
            if not data:
                continue
            try:
                r = parse(bytes(data))
            except HidFormatError as exc:
                self.drop("bad report", str(exc))
                continue
            imu.update(r, wrap)
            self.offer(
                time=time.monotonic(),
                source=self.source_id,
                orientation=imu.stick_orientation(),
                angular_velocity=imu.gyro,
                acceleration=imu.accel * 9.80665,
                touch=r.cross,
            )
