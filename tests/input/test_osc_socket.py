"""The OSC source's socket thread, through a real UDP socket on an ephemeral port.

Datagrams are sent from real client sockets on loopback *before* the thread starts, so they wait
in the kernel's queue and the thread reads them in order. The module's clock is a script
(:class:`ScriptedClock`): each read of ``time.monotonic`` takes the next scripted time, and the
last one asks the thread to stop, so a test knows exactly what the thread has done when it ends:
no sleeps, no timing assertions. A test waits at most a few seconds for the script to run out;
that bound only turns a hang into a failure.

Shown to fail (mutmut, docs/mutation.md): the sender id made of the UDP port instead of the
address, the port not handed to the gate (a second port of the phone then shares its budget),
no expiry after a datagram (a phone gone quiet kept its slot while another host sent) or after a
quiet read, the loop left after a read timeout or a socket error, the error not reported or not
paced, the receive buffer left at the system default (a 1000-datagram burst loses most of it),
the socket not closed by ``stop`` or after a failed bind.
"""

from __future__ import annotations

import errno
import gc
import socket
import threading
import warnings
from collections.abc import Callable, Iterator
from typing import Any

import pytest

from input import osc
from input.osc import STEP_BUDGET, OscSource
from input.sample import CONNECT, DISCONNECT, PoseSample

Message = Callable[..., bytes]
Clients = Callable[[], socket.socket]
LOOPBACK = "127.0.0.1"
PHONE = f"osc:{LOOPBACK}"
WAIT = 5.0  # seconds: the bound on a script that never runs out (a failure), never reached when passing


class ScriptedClock:
    """Stands in for the ``time`` module ``input.osc`` reads.

    ``monotonic()`` hands out ``times`` one per call (the thread reads it once per datagram and
    once per quiet read); an entry ``(t, action)`` also runs ``action`` first. Handing out the
    last time sets the source's ``stopping``, so the thread finishes that datagram and returns.
    ``sleep`` only records the pause asked for.
    """

    def __init__(self, src: OscSource, times: list[float | tuple[float, Callable[[], None]]]) -> None:
        self.src = src
        self.times = list(times)
        self.sleeps: list[float] = []
        self.done = threading.Event()

    def monotonic(self) -> float:
        if not self.times:  # past the script (a mutant reading the clock more often): stop there
            self.src.stopping.set()
            self.done.set()
            return 1e9
        entry = self.times.pop(0)
        if isinstance(entry, tuple):
            t, action = entry
            action()
        else:
            t = entry
        if not self.times:
            self.src.stopping.set()
            self.done.set()
        return t

    def sleep(self, seconds: float) -> None:
        self.sleeps.append(seconds)


Run = Callable[[OscSource, list[Any]], tuple[OscSource, ScriptedClock]]


@pytest.fixture
def clients() -> Iterator[Callable[[], socket.socket]]:
    """Client sockets, each on its own ephemeral port (a phone app, or a second one)."""
    made: list[socket.socket] = []

    def make() -> socket.socket:
        s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        s.bind((LOOPBACK, 0))
        made.append(s)
        return s

    yield make
    for s in made:
        s.close()


@pytest.fixture
def run(monkeypatch: pytest.MonkeyPatch) -> Iterator[Run]:
    """``run(src, times)``: start ``src``'s thread on a scripted clock; return once the script has run out."""
    started: list[OscSource] = []

    def go(src: OscSource, times: list[Any]) -> tuple[OscSource, ScriptedClock]:
        clock = ScriptedClock(src, times)
        monkeypatch.setattr(osc, "time", clock)
        src.start()
        started.append(src)
        assert clock.done.wait(WAIT), "the socket thread did not read what was sent"
        assert src._thread is not None
        src._thread.join(WAIT)
        assert not src._thread.is_alive()
        return src, clock

    yield go
    for s in started:
        s.stop()


def samples(items: list[PoseSample | tuple[str, str]]) -> list[PoseSample]:
    return [i for i in items if isinstance(i, PoseSample)]


def test_a_datagram_is_read_stamped_and_named_after_the_phones_address(run: Run, clients: Clients, pose: bytes) -> None:
    src = OscSource(host=LOOPBACK, port=0, admit_after=2)
    phone = clients()
    for _ in range(2):
        phone.sendto(pose, (LOOPBACK, src.port))
    run(src, [0.25, 0.5])
    items = src.drain()
    assert items[0] == (CONNECT, PHONE)
    got = samples(items)
    assert [(s.source, s.time) for s in got] == [(PHONE, 0.5)]
    assert src.status().drop_reasons == {"sender pending": 1}


def test_another_port_of_the_phone_spends_a_budget_of_its_own(run: Run, clients: Clients, pose: bytes) -> None:
    """The phone is admitted from one port; a flood from a second port of the same address is cut at
    its own step budget, and the phone's next datagram still goes through."""
    src = OscSource(host=LOOPBACK, port=0, admit_after=1)
    phone, other = clients(), clients()
    phone.sendto(pose, (LOOPBACK, src.port))
    for _ in range(STEP_BUDGET[0] + 1):
        other.sendto(pose, (LOOPBACK, src.port))
    phone.sendto(pose, (LOOPBACK, src.port))
    n = STEP_BUDGET[0] + 3
    run(src, [k / 1000 for k in range(n)])
    assert len(samples(src.drain())) == 1 + STEP_BUDGET[0] + 1
    status = src.status()
    assert status.drop_reasons == {"over budget": 1}
    assert status.last_error == f"over budget: {PHONE}:other"


def test_a_quiet_phone_is_released_while_another_host_keeps_sending(run: Run, clients: Clients, pose: bytes) -> None:
    """Expiry runs after every datagram, not only when the socket is quiet: a host that never stops
    sending cannot keep a silent phone's slot taken."""
    src = OscSource(host=LOOPBACK, port=0, admit_after=1, timeout=1.0)
    phone, other = clients(), clients()
    phone.sendto(pose, (LOOPBACK, src.port))
    other.sendto(b"garbage", (LOOPBACK, src.port))
    run(src, [0.0, 1.5])
    assert src.drain()[-1] == (DISCONNECT, PHONE)
    assert not src.status().connected


def test_a_quiet_socket_still_expires_the_phone_and_keeps_reading(run: Run, clients: Clients, pose: bytes) -> None:
    """Nothing arrives for a while (the read times out): the silent phone is released then, and the
    thread goes on reading: the phone back on a new UDP port (an app restarted) takes the free slot."""
    src = OscSource(host=LOOPBACK, port=0, admit_after=1, timeout=1.0)
    phone, restarted = clients(), clients()
    phone.sendto(pose, (LOOPBACK, src.port))
    times: list[Any] = [0.0, (1.5, lambda: restarted.sendto(pose, (LOOPBACK, src.port))), 1.6]
    run(src, times)
    items = src.drain()
    assert [i if isinstance(i, tuple) else i.time for i in items] == [
        (CONNECT, PHONE),
        0.0,
        (DISCONNECT, PHONE),
        (CONNECT, PHONE),
        1.6,
    ]


class FailingOnce:
    """The real socket, whose first read fails as a dropped network interface would."""

    def __init__(self, sock: socket.socket, on_fail: Callable[[], None] = lambda: None) -> None:
        self.sock = sock
        self.failed = False
        self.on_fail = on_fail

    def recvfrom(self, size: int) -> tuple[bytes, Any]:
        if not self.failed:
            self.failed = True
            self.on_fail()
            raise OSError(errno.ENETDOWN, "Network is down")
        return self.sock.recvfrom(size)

    def close(self) -> None:
        self.sock.close()


def test_a_socket_error_is_reported_and_the_thread_goes_on_after_a_pause(
    run: Run, clients: Clients, pose: bytes
) -> None:
    src = OscSource(host=LOOPBACK, port=0, admit_after=1)
    src._sock = FailingOnce(src._sock)  # type: ignore[assignment]  # the real socket behind one failure
    clients().sendto(pose, (LOOPBACK, src.port))
    _, clock = run(src, [0.0])
    assert src.status().last_error == "socket error: [Errno 100] Network is down"
    assert len(clock.sleeps) == 1 and 0 < clock.sleeps[0] <= 0.1  # paced: a broken socket is not spun on
    assert [i if isinstance(i, tuple) else i.time for i in src.drain()] == [(CONNECT, PHONE), 0.0]


def test_a_socket_closing_under_stop_ends_the_thread_quietly(monkeypatch: pytest.MonkeyPatch) -> None:
    """``stop`` closes the socket; a read failing because of it is the end, not an error to report."""
    src = OscSource(host=LOOPBACK, port=0)
    src._sock = FailingOnce(src._sock, on_fail=src.stopping.set)  # type: ignore[assignment]  # fails as stop closes it
    clock = ScriptedClock(src, [])
    monkeypatch.setattr(osc, "time", clock)
    src._run()
    assert src.status().last_error == "" and clock.sleeps == []
    src.stop()


def test_stop_releases_the_port(pose: bytes) -> None:
    src = OscSource(host=LOOPBACK, port=0).start()
    port = src.port
    src.stop()
    again = OscSource(host=LOOPBACK, port=port)  # an OSError here: the old socket still holds it
    again.stop()


def test_a_taken_port_is_a_one_line_error_and_leaks_no_socket() -> None:
    holder = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    holder.bind((LOOPBACK, 0))
    port = holder.getsockname()[1]
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            with pytest.raises(OSError, match=f"^cannot listen for OSC on {LOOPBACK}:{port}: .*Address already in use"):
                OscSource(host=LOOPBACK, port=port)
            gc.collect()
        assert not [w for w in caught if issubclass(w.category, ResourceWarning)]
    finally:
        holder.close()


def test_a_burst_is_held_by_the_receive_buffer_until_the_thread_reads_it(
    run: Run, clients: Clients, pose: bytes
) -> None:
    """1000 small datagrams sent at once (a Wi-Fi bunch, or a stall of the thread) all reach the gate:
    the default receive buffer (about 208 KB here) holds only 256 of them."""
    n = 1000
    src = OscSource(host=LOOPBACK, port=0, admit_after=1, max_rate=1e6)
    phone = clients()
    for _ in range(n):
        phone.sendto(pose, (LOOPBACK, src.port))
    run(src, [k * 1e-5 for k in range(n)])
    status = src.status()
    assert status.packets + status.dropped == n
