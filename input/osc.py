"""Phones over OSC/UDP: a socket thread that validates, rate-limits and decodes packets.

Binding: ``host`` defaults to ``127.0.0.1``; a phone on the LAN needs ``0.0.0.0``
(``--osc-host 0.0.0.0``; the pairing overlay says so). Port 9000 by default (the
Sensors2OSC default; point ZIG SIM, whose own default is 3333, at it).

Per datagram the thread: checks the sender, applies a per-sender rate limit (token
bucket), then hands the bytes to :class:`input.osc_profiles.OscDecoder`. Garbage,
truncated packets, wrong types, NaN/inf and non-unit quaternions are counted in the
status with their reason and dropped; the thread never raises out.

Sender policy: a new address is a *candidate* until it has sent ``admit_after`` valid
pose samples; only then does it take one of the ``max_senders`` slots (the session
then follows it, and the status reports it connected). So garbage, or a single stray
datagram, from any host on the LAN cannot claim the phone's slot: only a real pose
stream can. Once the slots are taken, other addresses are refused and listed in the
status's ``locked_out`` (the overlay names them). At most :data:`MAX_CANDIDATES`
addresses are candidates at once; a candidate quiet for ``timeout`` seconds is forgotten.

Bounded work: a datagram over :data:`MAX_DATAGRAM` bytes, a bundle nested deeper than
:data:`MAX_BUNDLE_DEPTH` or holding more than :data:`MAX_MESSAGES` messages is dropped
before python-osc parses it (the structure is walked iteratively first). Between two
drains of the hub (one simulation step) each admitted sender may have
:data:`STEP_BUDGET` datagrams, messages and bytes decoded, and each candidate
:data:`CANDIDATE_BUDGET`; the excess is dropped and counted ("over budget"). Decoding runs on the
socket thread, but it holds the interpreter lock the simulation needs: unbounded, a
flood of 62 KB bundles held the game at 34 steps/s. Per sender, so a flood from one
address does not spend the budget of the phone that plays.

An admitted sender that goes quiet for ``timeout`` seconds (2 s by default) is reported
disconnected (its stick lets go) and its slot is released: the next phone that sends a
valid pose stream gets it (the same phone too, after :data:`ADMIT_AFTER` samples).

Spoofing: a phone is one address (``osc:IP``), and the UDP port it was admitted from is
remembered. Datagrams from other ports of the same address (a forger on the LAN using the
phone's IP, or a client that opens a socket per message such as ``oscsend``) have a rate
limit and decoding budget of their own, so a flood of them cannot spend the phone's; their
valid poses are the phone's too (a forger able to send those could anyway), garbage from
them keeps nothing alive. A forger that also guesses the port shares the phone's budget.
"""

from __future__ import annotations

import socket
import time

from input.osc_profiles import OscDecoder
from input.sample import PoseSample
from input.source import PoseSource

__all__ = [
    "OscSource",
    "DEFAULT_PORT",
    "ADMIT_AFTER",
    "MAX_CANDIDATES",
    "MAX_DATAGRAM",
    "MAX_BUNDLE_DEPTH",
    "MAX_MESSAGES",
    "STEP_BUDGET",
    "CANDIDATE_BUDGET",
    "bundle_shape",
]

DEFAULT_PORT = 9000
ADMIT_AFTER = 3  # valid samples: 50 ms of a 60 Hz phone
MAX_CANDIDATES = 8
# Phone apps send a few hundred bytes per tick (a ZIG SIM bundle with every sensor is ~1 KB).
MAX_DATAGRAM = 8192
MAX_BUNDLE_DEPTH = 2
MAX_MESSAGES = 32
# Per admitted sender and step: datagrams, messages, bytes. A 60 Hz phone needs one datagram
# of a few messages per step (a ZIG SIM bundle holds about ten); Sensors2OSC sends one
# datagram per sensor, up to the rate limit's 400/s; the rest is slack for Wi-Fi bunching.
STEP_BUDGET = (8, 32, 8192)
# Per candidate and step: enough for a phone to prove its pose stream (a whole ZIG SIM bundle),
# and no more, as a candidate is anyone.
CANDIDATE_BUDGET = (2, 16, 4096)
_BUNDLE = b"#bundle\x00"


def bundle_shape(data: bytes) -> tuple[int, str]:
    """How many messages ``data`` holds, and why it is too big a bundle to parse (``""`` if it is not).

    Walked without recursion and without parsing: only sizes are checked here; whatever
    else is wrong, python-osc reports while parsing.
    """
    todo = [(0, len(data), 1)]
    messages = 0
    while todo:
        start, end, depth = todo.pop()
        if data[start : start + 8] != _BUNDLE:
            messages += 1
            continue
        if depth > MAX_BUNDLE_DEPTH:
            return messages, "bundle too deep"
        pos = start + 16  # past the tag and the time tag
        while pos + 4 <= end:
            n = int.from_bytes(data[pos : pos + 4], "big")
            pos += 4
            if n <= 0 or pos + n > end:
                break
            if messages + len(todo) >= MAX_MESSAGES:
                return messages, "bundle too large"
            todo.append((pos, pos + n, depth + 1))
            pos += n
    return messages, ""


class OscSource(PoseSource):
    """UDP OSC receiver for phone apps.

    Args:
        host: bind address (``0.0.0.0`` for phones on the LAN; tests use ``127.0.0.1``).
        port: UDP port; 0 picks a free one (read :attr:`port` after :meth:`start`).
        max_senders: how many senders may drive sticks (1 = lock to the first valid stream).
        max_rate: packets per second accepted per sender (burst of one second).
        timeout: seconds of silence before a sender counts as disconnected.
        gyrosc_order: GyrOSC quaternion order.
        admit_after: valid samples a new sender must send before it takes a slot.

    Raises:
        ValueError: ``max_senders`` or ``admit_after`` below 1, a port outside 0..65535.
        OSError: the port cannot be bound.
    """

    def __init__(
        self,
        host: str = "127.0.0.1",
        port: int = DEFAULT_PORT,
        max_senders: int = 1,
        max_rate: float = 400.0,
        timeout: float = 2.0,
        gyrosc_order: str = "wxyz",
        capacity: int = 256,
        admit_after: int = ADMIT_AFTER,
    ) -> None:
        if max_senders < 1:
            raise ValueError(
                f"the number of OSC senders must be at least 1 (0 would refuse every phone), not {max_senders}"
            )
        if admit_after < 1:
            raise ValueError(f"admit_after must be at least 1, not {admit_after}")
        if not 0 <= port <= 65535:
            raise ValueError(f"OSC port must be 0..65535, not {port}")
        super().__init__(f"osc {host}:{port}", capacity)
        self.host = host
        self.max_senders = max_senders
        self.max_rate = max_rate
        self.timeout = timeout
        self.admit_after = admit_after
        self.decoder = OscDecoder(on_drop=self.drop, gyrosc_order=gyrosc_order)
        self._senders: dict[str, list[float]] = {}  # sender -> [tokens, last refill, last seen]
        self._admitted: list[str] = []
        self._valid: dict[str, int] = {}  # candidate -> valid samples so far
        self._active: set[str] = set()
        self._budget: dict[str, list[int]] = {}  # sender -> what is left to decode this step
        self._port: dict[str, int] = {}  # admitted sender -> the UDP port it was admitted from
        self._strangers: dict[str, list[float]] = {}  # "<sender>:other" -> [tokens, last refill]
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
            self.handle_datagram(data, f"osc:{addr[0]}", now, addr[1])
            self._expire(now)

    def handle_datagram(self, data: bytes, sender: str, now: float, port: int = 0) -> None:
        """Validate and decode one datagram from ``sender``'s UDP ``port`` (the socket thread's work)."""
        proven = self._port.get(sender)
        if proven is not None and port != proven:
            self._from_other_port(data, sender, now, port)
            return
        state = self._senders.get(sender)
        if state is None:
            if len(self._admitted) >= self.max_senders:
                self._lock_out(sender)
                return
            if len(self._valid) >= MAX_CANDIDATES:
                self.drop("too many senders", sender)
                return
            state = self._senders[sender] = [self.max_rate, now, now]
            self._valid[sender] = 0
        tokens = min(self.max_rate, state[0] + (now - state[1]) * self.max_rate)
        state[1], state[2] = now, now
        if tokens < 1.0:
            state[0] = tokens
            self.drop("rate limit", sender)
            return
        state[0] = tokens - 1.0
        if not self._affordable(data, sender):
            return
        sample = self.decoder.decode(data, sender, now)
        if sender in self._valid and not self._admit(sender, sample is not None, port):
            return
        self._deliver(sender, sample)

    def _deliver(self, sender: str, sample: PoseSample | None) -> None:
        """An admitted sender's datagram was decoded: it is connected, and its sample is queued."""
        if sender not in self._active:
            self._active.add(sender)
            self.connected(sender)
        if sample is not None:
            self.push(sample)

    def _from_other_port(self, data: bytes, sender: str, now: float, port: int) -> None:
        """A datagram from a port other than the one ``sender`` was admitted from (a forger of its
        address, or a client that opens a socket per message): decoded on a rate and budget of its
        own, so it never spends the phone's; only a valid pose keeps the slot alive."""
        key = f"{sender}:other"
        bucket = self._strangers.setdefault(key, [self.max_rate, now])
        tokens = min(self.max_rate, bucket[0] + (now - bucket[1]) * self.max_rate)
        bucket[1] = now
        if tokens < 1.0:
            bucket[0] = tokens
            self.drop("rate limit", f"{sender}:{port}")
            return
        bucket[0] = tokens - 1.0
        if not self._affordable(data, key, candidate=False):
            return
        sample = self.decoder.decode(data, sender, now)
        if sample is not None:  # a valid pose: the phone itself, or a forger that could send it anyway
            self._senders[sender][2] = now
            self._deliver(sender, sample)

    def _affordable(self, data: bytes, sender: str, candidate: bool | None = None) -> bool:
        """Whether ``data`` is small enough, and this step's budget holds it (then spend it)."""
        if len(data) > MAX_DATAGRAM:
            self.drop("oversize packet", f"{sender}: {len(data)} bytes")
            return False
        messages, problem = bundle_shape(data)
        if problem:
            self.drop(problem, sender)
            return False
        if candidate is None:
            candidate = sender in self._valid
        left = self._budget.setdefault(sender, list(CANDIDATE_BUDGET if candidate else STEP_BUDGET))
        if left[0] < 1 or left[1] < messages or left[2] < len(data):
            self.drop("over budget", sender)
            return False
        left[0] -= 1
        left[1] -= messages
        left[2] -= len(data)
        return True

    def drain(self) -> list[PoseSample | tuple[str, str]]:
        """What was queued since the last step; the decoding budgets start again for the next."""
        self._budget = {}
        return super().drain()

    def _admit(self, sender: str, valid: bool, port: int) -> bool:
        """Count a candidate's valid sample; whether it now holds a slot (its stream's port: ``port``)."""
        if not valid:
            return False
        self._valid[sender] += 1
        if self._valid[sender] < self.admit_after:
            self.drop("sender pending", sender)
            return False
        del self._valid[sender]
        self._admitted.append(sender)
        self._port[sender] = port
        self._budget.pop(sender, None)  # from now on an admitted sender's budget
        if len(self._admitted) >= self.max_senders:  # the slots are taken: the other candidates are out
            for other in list(self._valid):
                self._forget(other)
        return True

    def _forget(self, sender: str) -> None:
        self._valid.pop(sender, None)
        self._senders.pop(sender, None)
        self._port.pop(sender, None)
        self._strangers.pop(f"{sender}:other", None)
        self.decoder.senders.pop(sender, None)

    def _lock_out(self, sender: str) -> None:
        self.drop("other sender", f"{sender} (locked to {', '.join(self._admitted)})")
        with self._lock:
            seen = self._status.locked_out
            if sender not in seen:
                seen[:] = [*seen[-3:], sender]  # the latest few, for the overlay

    def _expire(self, now: float) -> None:
        for sender in [s for s in self._valid if now - self._senders[s][2] > self.timeout]:
            self._forget(sender)
        for sender in [s for s in self._admitted if now - self._senders[s][2] > self.timeout]:
            self._admitted.remove(sender)  # silent: the slot goes to the next phone with a valid stream
            self._forget(sender)
            if sender in self._active:
                self._active.discard(sender)
                self.disconnected(sender)
