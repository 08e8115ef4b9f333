"""Phones over OSC/UDP: a socket thread that validates, rate-limits and decodes packets.

Binding: ``host`` defaults to ``127.0.0.1``; a phone on the LAN needs ``0.0.0.0``
(``--osc-host 0.0.0.0``; the pairing overlay says so). Port 9000 by default (the
Sensors2OSC default; point ZIG SIM, whose own default is 3333, at it).

Per datagram the thread: checks the sender (locked to the first one unless
``max_senders`` allows more), applies a per-sender rate limit (token bucket), then
hands the bytes to :class:`input.osc_profiles.OscDecoder`. Garbage, truncated
packets, wrong types, NaN/inf and non-unit quaternions are counted in the status
with their reason and dropped; the thread never raises out.

A sender that goes quiet for ``timeout`` seconds is reported disconnected (its stick
lets go); its next packet reconnects it.
"""

from __future__ import annotations

import socket
import time

from input.osc_profiles import OscDecoder
from input.source import PoseSource

__all__ = ["OscSource", "DEFAULT_PORT"]

DEFAULT_PORT = 9000


class OscSource(PoseSource):
    """UDP OSC receiver for phone apps.

    Args:
        host: bind address (``0.0.0.0`` for phones on the LAN; tests use ``127.0.0.1``).
        port: UDP port; 0 picks a free one (read :attr:`port` after :meth:`start`).
        max_senders: how many senders may drive sticks (1 = lock to the first).
        max_rate: packets per second accepted per sender (burst of one second).
        timeout: seconds of silence before a sender counts as disconnected.
        gyrosc_order: GyrOSC quaternion order.
    """

    def __init__(self, host: str = "127.0.0.1", port: int = DEFAULT_PORT, max_senders: int = 1,
                 max_rate: float = 400.0, timeout: float = 2.0, gyrosc_order: str = "wxyz",
                 capacity: int = 256) -> None:
        super().__init__(f"osc {host}:{port}", capacity)
        self.host = host
        self.max_senders = max_senders
        self.max_rate = max_rate
        self.timeout = timeout
        self.decoder = OscDecoder(on_drop=self.drop, gyrosc_order=gyrosc_order)
        self._senders: dict[str, list[float]] = {}  # sender -> [tokens, last refill, last seen]
        self._active: set[str] = set()
        self._sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        try:
            self._sock.bind((host, port))
        except OSError as exc:
            self._sock.close()
            raise OSError(f"cannot listen for OSC on {host}:{port}: {exc}") from exc
        self._sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 20)  # absorb bursts (capped by the OS)
        self._sock.settimeout(0.05)
        self.port: int = self._sock.getsockname()[1]
        self.name = f"osc {host}:{self.port}"
        self._status.name = self.name
        self._status.connected = False

    def stop(self, timeout: float = 2.0) -> None:
        """Stop the thread and close the socket."""
        super().stop(timeout)
        self._sock.close()

    def _run(self) -> None:
        while not self.stopping.is_set():
            try:
                data, addr = self._sock.recvfrom(65536)
            except TimeoutError:
                self._expire(time.monotonic())
                continue
            except OSError as exc:
                if self.stopping.is_set():
                    return
                self.error(f"socket error: {exc}")
                time.sleep(0.05)
                continue
            now = time.monotonic()
            # One id per phone address: an app restarted on a new UDP port is still the same phone.
            self.handle_datagram(data, f"osc:{addr[0]}", now)
            self._expire(now)

    def handle_datagram(self, data: bytes, sender: str, now: float) -> None:
        """Validate and decode one datagram (the socket thread's work; callable from tests)."""
        state = self._senders.get(sender)
        if state is None:
            if len(self._senders) >= self.max_senders:
                self.drop("other sender", f"{sender} (locked to {', '.join(self._senders)})")
                return
            state = self._senders[sender] = [self.max_rate, now, now]
        tokens = min(self.max_rate, state[0] + (now - state[1]) * self.max_rate)
        state[1], state[2] = now, now
        if tokens < 1.0:
            state[0] = tokens
            self.drop("rate limit", sender)
            return
        state[0] = tokens - 1.0
        if sender not in self._active:
            self._active.add(sender)
            self.connected(sender)
        sample = self.decoder.decode(data, sender, now)
        if sample is not None:
            self.push(sample)

    def _expire(self, now: float) -> None:
        for sender in [s for s in self._active if now - self._senders[s][2] > self.timeout]:
            self._active.discard(sender)
            self.disconnected(sender)  # the lock stays: the first sender is the one that comes back
