"""Serial IMUs (Arduino/ESP32 sketches) as a pose source, reconnecting after a cable pull.

The device thread opens the port with ``serial.serial_for_url`` (so ``/dev/ttyUSB0``,
a socat pty and ``loop://`` all work), sends one byte to wake i2cdevlib sketches
(they wait for a character before starting the DMP), feeds whatever arrives to
:class:`input.serial_parse.SerialStreamParser` and pushes one sample per reading.
When the port errors or vanishes it reports a disconnect, closes, and retries every
``retry`` seconds until the device is back.

IMU quaternions are taken as device→world with world Z up (MPU6050 DMP, BNO055),
and the stick points out of the board's +Y edge, like a phone (see
:mod:`input.phone_frames`); tap-to-calibrate fixes the heading.
"""

from __future__ import annotations

import time

import numpy as np
import serial

from input.phone_frames import phone_to_stick, z_up_to_engine
from input.serial_parse import SerialStreamParser
from input.source import PoseSource

__all__ = ["SerialSource"]


class SerialSource(PoseSource):
    """Reads an IMU over a serial port.

    Args:
        port: device path or pyserial URL.
        baudrate: 115200 for i2cdevlib, 9600 for Adafruit's webserial sketch.
        retry: seconds between reconnection attempts.
        wake: send one byte after opening (i2cdevlib waits for it).
    """

    def __init__(
        self, port: str, baudrate: int = 115200, retry: float = 0.5, wake: bool = True, capacity: int = 256
    ) -> None:
        super().__init__(f"serial {port}", capacity)
        self.port = port
        self.baudrate = baudrate
        self.retry = retry
        self.wake = wake
        self.source_id = f"serial:{port}"
        self.parser = SerialStreamParser()
        self.reconnects = 0

    def _open(self) -> serial.SerialBase | None:
        try:
            ser = serial.serial_for_url(self.port, baudrate=self.baudrate, timeout=0.05)
        except (serial.SerialException, OSError, ValueError) as exc:
            self.error(f"cannot open {self.port}: {exc}")
            return None
        if self.wake:
            try:
                ser.write(b"\n")
            except (serial.SerialException, OSError):
                pass  # write-only failure is not fatal; reading will tell
        return ser

    def _run(self) -> None:
        while not self.stopping.is_set():
            ser = self._open()
            if ser is None:
                self.stopping.wait(self.retry)
                continue
            self.connected(self.source_id)
            self.parser = SerialStreamParser()
            try:
                self._read_loop(ser)
            except (serial.SerialException, OSError) as exc:
                self.error(f"{self.port} lost: {exc}")
            finally:
                try:
                    ser.close()
                except (serial.SerialException, OSError):
                    pass
            self.disconnected(self.source_id)
            if not self.stopping.is_set():
                self.reconnects += 1
                self.stopping.wait(self.retry)

    def _read_loop(self, ser: serial.SerialBase) -> None:
        while not self.stopping.is_set():
            chunk = ser.read(max(1, ser.in_waiting))
            if not chunk:
                continue
            before = dict(self.parser.skipped)
            for r in self.parser.feed(chunk):
                self.offer(
                    time=time.monotonic(),
                    source=self.source_id,
                    orientation=phone_to_stick(np.array(r.quaternion)),
                    position=None if r.position is None else z_up_to_engine(r.position),
                    touch=r.touch,
                )
            for reason, n in self.parser.skipped.items():
                for _ in range(n - before.get(reason, 0)):
                    self.drop(reason)
