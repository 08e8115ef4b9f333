"""The pose-source interface: device I/O on its own thread, samples into a bounded queue.

Every backend (OSC, HID, serial, mouse, replay) is a :class:`PoseSource`. Device
threads only *push*; the :class:`input.hub.InputHub` *drains* once per fixed step on
the simulation thread. The queue is a bounded ``deque`` (its ``append``/``popleft``
are atomic in CPython), so a flood of packets costs a bounded amount of memory and
drain time: the oldest samples fall off and are counted as dropped.

Status (connected, packets/s, dropped with reasons, last error) is kept here for
the overlay; it is display data and never enters the simulation.
"""

from __future__ import annotations

import logging
import threading
import time
from collections import deque

from input.sample import CONNECT, DISCONNECT, PoseSample, SourceStatus

__all__ = ["PoseSource", "RateMeter"]

log = logging.getLogger("puppetphone.input")


class RateMeter:
    """Packets per second over a sliding window (wall clock: display only)."""

    def __init__(self, window: float = 1.0) -> None:
        self.window = window
        self._times: deque[float] = deque()
        self._lock = threading.Lock()

    def tick(self, now: float | None = None) -> None:
        """Count one packet."""
        now = time.monotonic() if now is None else now
        with self._lock:
            self._times.append(now)
            self._trim(now)

    def rate(self, now: float | None = None) -> float:
        """Packets in the last ``window`` seconds, per second."""
        now = time.monotonic() if now is None else now
        with self._lock:
            self._trim(now)
            return len(self._times) / self.window

    def _trim(self, now: float) -> None:
        while self._times and self._times[0] < now - self.window:
            self._times.popleft()


class PoseSource:
    """Base of every pose source: a bounded queue of samples and events, and a status.

    Subclasses run their device loop in :meth:`_run` (on a daemon thread started by
    :meth:`start`) and call :meth:`push`, :meth:`connected` / :meth:`disconnected` and
    :meth:`drop`. ``_run`` must return soon after :attr:`stopping` is set.

    Args:
        name: shown in the overlay and used as the default source id.
        capacity: queue length; older items are dropped (and counted) beyond it.
    """

    threaded = True
    #: A person drives it in real time though it has no device thread (the mouse): a run is paced for it.
    person = False

    def __init__(self, name: str, capacity: int = 256) -> None:
        self.name = name
        self._queue: deque[PoseSample | tuple[str, str]] = deque(maxlen=capacity)
        self._status = SourceStatus(name=name)
        self._meter = RateMeter()
        self._lock = threading.Lock()
        self._thread: threading.Thread | None = None
        self.stopping = threading.Event()
        self.arrived: threading.Event | None = None  # set on each reading: the hub's wake-up for a paced step

    # -- lifecycle -------------------------------------------------------------------
    def start(self) -> PoseSource:
        """Start the device thread (no-op for sources fed from the main thread)."""
        if self.threaded and self._thread is None:
            self._thread = threading.Thread(target=self._guarded_run, name=f"input-{self.name}", daemon=True)
            self._thread.start()
        return self

    def stop(self, timeout: float = 2.0) -> None:
        """Ask the device thread to finish and wait for it."""
        self.stopping.set()
        if self._thread is not None:
            self._thread.join(timeout)
            self._thread = None

    def __enter__(self) -> PoseSource:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def _guarded_run(self) -> None:
        try:
            self._run()
        except Exception as exc:  # a device thread must never die silently
            self.error(f"{type(exc).__name__}: {exc}")
            log.exception("input source %s stopped", self.name)

    def _run(self) -> None:
        raise NotImplementedError

    # -- producer side (device thread) ------------------------------------------------
    def push(self, sample: PoseSample) -> None:
        """Queue a sample for the next step."""
        self._enqueue(sample)
        self._meter.tick()
        with self._lock:
            self._status.packets += 1
        if self.arrived is not None:
            self.arrived.set()

    def offer(self, **fields: object) -> PoseSample | None:
        """Build a :class:`PoseSample` from ``fields`` and queue it, or drop and count it.

        Device threads use this instead of building samples themselves: a reading that
        fails the sample's checks (out of range, not finite) is a bad packet to count,
        never an exception that ends the thread.
        """
        try:
            sample = PoseSample(**fields)  # type: ignore[arg-type]  # PoseSample checks them: a bad one is dropped
        except ValueError as exc:
            self.drop("invalid sample", str(exc)[:200])
            return None
        self.push(sample)
        return sample

    def connected(self, source_id: str | None = None) -> None:
        """Report that a device (or sender) appeared."""
        with self._lock:
            self._status.connected = True
        self._enqueue((CONNECT, source_id or self.name))

    def disconnected(self, source_id: str | None = None) -> None:
        """Report that a device went away (the stick it drove lets go)."""
        with self._lock:
            self._status.connected = False
        self._enqueue((DISCONNECT, source_id or self.name))

    def drop(self, reason: str, detail: str = "") -> None:
        """Count a rejected packet and log why (rate-limited by the logger's level)."""
        with self._lock:
            self._status.dropped += 1
            self._status.drop_reasons[reason] = self._status.drop_reasons.get(reason, 0) + 1
            self._status.last_error = f"{reason}: {detail}" if detail else reason
        log.debug("%s dropped a packet: %s %s", self.name, reason, detail)

    def error(self, message: str) -> None:
        """Remember the last device error (open failed, cable pulled …)."""
        with self._lock:
            self._status.last_error = message
        log.info("%s: %s", self.name, message)

    def _enqueue(self, item: PoseSample | tuple[str, str]) -> None:
        if len(self._queue) == self._queue.maxlen:
            self.drop("queue full")
        self._queue.append(item)

    # -- consumer side (simulation thread) ---------------------------------------------
    def drain(self) -> list[PoseSample | tuple[str, str]]:
        """Everything queued since the last drain, oldest first."""
        out = []
        q = self._queue
        while q:
            try:
                out.append(q.popleft())
            except IndexError:  # emptied by a concurrent drain
                break
        return out

    def status(self) -> SourceStatus:
        """A snapshot of the status for display."""
        with self._lock:
            s = SourceStatus(
                **{
                    **self._status.__dict__,
                    "drop_reasons": dict(self._status.drop_reasons),
                    "locked_out": list(self._status.locked_out),
                }
            )
        s.packets_per_s = self._meter.rate()
        return s
