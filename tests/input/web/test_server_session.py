"""One phone's connection without a socket: ``WebSource._connection`` and ``_stream`` driven by a fake WebSocket.

``test_server.py`` and ``test_scene_push.py`` prove the same rules end to end over TLS (about a second
a test); here the page's side is a queue the test fills and a list of what the server sent, all in one
asyncio loop, so each test takes milliseconds and the mutation run (docs/mutation.md, sixth round) can
afford them for every mutant of the connection code. Nothing waits on the wall clock except the silent
controller, whose ``silent_after`` is the code's own timer (50 ms); every other wait is on a condition,
under a ten-second guard that only a broken server reaches.

Each rule was shown to fail by its mutmut mutants (docs/mutation.md names them): the first free slot
taken from 2 or from 0, a taken slot given again, the ``{"taken": true}`` answer or its close code
changed, the hello or the pong changed or not sent, a ``None`` sent for a reading, the silent phone's
puppet freed only after its close (or under another name), the close reasons, the clock of a phone
that left kept for the next, frames sent past ``FRAMES_IN_FLIGHT`` or held after the ack that frees
them, the GLB or a delta built from other arguments, the same step sent twice, the bucket's arithmetic.
"""

from __future__ import annotations

import asyncio
import inspect
import json
import threading
from collections.abc import Awaitable, Callable, Coroutine, Iterator
from typing import Any

import numpy as np
import pytest
from websockets.exceptions import ConnectionClosed
from websockets.frames import Close, CloseCode

from engine.render.scene import RenderScene
from engine.render.snowfall import Snowfall
from input.sample import PoseSample
from input.source import PoseSource
from input.web.cert import WebCertificate, load_or_create
from input.web.protocol import Ack, WebMessageError, parse_message
from input.web.scene_glb import scene_glb
from input.web.scene_stream import CameraPose, SceneState, decode_frame, encode_frame, quantise
from input.web.server import FRAMES_IN_FLIGHT, WebSource

CAM = CameraPose((0.0, 1.5, 4.0), (1.0, 0.0, 0.0, 0.0), 60.0)
ADDRESS = ("192.0.2.7", 50123)
GUARD = 10.0  # seconds: every wait here is on a condition the loop reaches at once, or the server is broken


def _reading(t: float = 0.0, **extra: Any) -> str:
    return json.dumps({"seq": 0, "t": t, "kind": "orientation", "o": [0.0, 10.0, 0.0], "touch": False, **extra})


class _Page:
    """Stands for websockets' server connection: ``feed`` is what the page sends (a message, or an
    exception ``recv`` raises), ``sent`` what the server sent, ``closed`` its close calls with what the
    server held at that moment (``on_close``)."""

    remote_address = ADDRESS

    def __init__(self, on_close: Callable[[], object] = lambda: None) -> None:
        self.inbox: asyncio.Queue[str | bytes | BaseException] = asyncio.Queue()
        self.sent: list[str | bytes] = []
        self.closed: list[tuple[int, str, object]] = []
        self.send_error: BaseException | None = None
        self._on_close = on_close
        self._activity = asyncio.Event()

    def feed(self, *items: str | bytes | BaseException) -> None:
        for item in items:
            self.inbox.put_nowait(item)

    async def recv(self) -> str | bytes:
        item = await self.inbox.get()
        if isinstance(item, BaseException):
            raise item
        return item

    async def send(self, data: str | bytes) -> None:
        if self.send_error is not None:
            raise self.send_error
        self.sent.append(data)
        self._activity.set()

    async def close(self, code: int = 1000, reason: str = "") -> None:
        self.closed.append((code, reason, self._on_close()))
        self._activity.set()

    async def until(self, done: Callable[[], bool]) -> None:
        """Wait until ``done()`` after something was sent or closed (at most :data:`GUARD` seconds)."""

        async def wait() -> None:
            while not done():
                self._activity.clear()
                await self._activity.wait()

        await asyncio.wait_for(wait(), GUARD)


class _Clock:
    def __init__(self, now: float = 100.0) -> None:
        self.now = now

    def __call__(self) -> float:
        return self.now


@pytest.fixture(scope="module")
def certificate(tmp_path_factory: pytest.TempPathFactory) -> WebCertificate:
    return load_or_create([], tmp_path_factory.mktemp("web"))


@pytest.fixture
def make(certificate: WebCertificate) -> Iterator[Callable[..., WebSource]]:
    """Sources bound to an OS-assigned port and never started: the test runs their connection code itself."""
    made: list[WebSource] = []

    def build(**kwargs: Any) -> WebSource:
        src = WebSource(**{"port": 0, "certificate": certificate, "max_rate": 1000.0, "clock": _Clock(), **kwargs})
        made.append(src)
        return src

    yield build
    for src in made:
        src.stop()


def _run(scenario: Callable[[], Coroutine[Any, Any, None]]) -> None:
    asyncio.run(scenario())


async def _settle() -> None:
    """Let every callback and task that is ready run to its next wait (no time passes: nothing here sleeps)."""
    for _ in range(50):
        await asyncio.sleep(0)


def _others() -> list[asyncio.Task[Any]]:
    return [t for t in asyncio.all_tasks() if t is not asyncio.current_task() and not t.done()]


def _events(src: WebSource) -> list[tuple[str, str]]:
    return [item for item in src.drain() if isinstance(item, tuple)]


def _closed_by_page(code: int = 1000) -> ConnectionClosed:
    return ConnectionClosed(Close(code, "bye"), Close(code, "bye"), True)


async def _open(src: WebSource, page: _Page) -> asyncio.Task[None]:
    """Start ``page``'s connection on this loop (as ``_serve`` would) and wait for its first answer."""
    src._loop = asyncio.get_running_loop()
    task = asyncio.create_task(src._connection(page))
    await page.until(lambda: bool(page.sent or page.closed))
    return task


async def _end(task: Awaitable[None]) -> None:
    await asyncio.wait_for(task, GUARD)
    await _settle()


# -- slots ------------------------------------------------------------------------------------------


@pytest.mark.parametrize(("max_controllers", "held", "given"), [(1, [], 1), (2, [1], 2), (3, [1, 3], 2), (3, [2], 1)])
def test_a_phone_gets_the_first_free_puppet_and_gives_it_back_when_it_leaves(
    make: Callable[..., WebSource], max_controllers: int, held: list[int], given: int
) -> None:
    """Slots count from 1 (``web:1`` is the first puppet); the lowest free one is given, the others are
    left as they were; the page's close frees that slot, once, with no drop and no error."""
    src = make(max_controllers=max_controllers)
    others = {slot: object() for slot in held}
    src._slots.update(others)

    async def scenario() -> None:
        page = _Page()
        task = await _open(src, page)
        assert page.sent == [json.dumps({"hello": f"web:{given}"})] and not page.closed
        assert src._slots == {**others, given: page} and src.viewers == 1
        page.feed(_closed_by_page())
        await _end(task)
        assert src._slots == others and src.viewers == 0
        assert not _others(), "the frame sender outlived its connection"

    _run(scenario)
    assert _events(src) == [("connect", f"web:{given}"), ("disconnect", f"web:{given}")]
    status = src.status()
    assert status.dropped == 0 and status.last_error == ""


@pytest.mark.parametrize(("max_controllers", "held"), [(1, [1]), (2, [1, 2])])
def test_a_phone_beyond_the_puppets_is_told_they_are_taken_and_closed(
    make: Callable[..., WebSource], max_controllers: int, held: list[int]
) -> None:
    src = make(max_controllers=max_controllers)
    others = {slot: object() for slot in held}
    src._slots.update(others)

    async def scenario() -> None:
        page = _Page()
        await _end(await _open(src, page))
        assert page.sent == ['{"taken": true}']
        assert [c[:2] for c in page.closed] == [(4001, "every puppet has a controller")]
        assert src._slots == others and src.viewers == 0 and not _others()

    _run(scenario)
    assert _events(src) == []
    status = src.status()
    assert status.drop_reasons == {"every puppet taken": 1}
    assert status.last_error == f"every puppet taken: {ADDRESS}"


# -- how a connection ends --------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("ending", "drops", "error"),
    [
        (_closed_by_page(), {}, ""),
        (ConnectionClosed(Close(1000, ""), None), {}, ""),  # the page's close, ours never sent
        (ConnectionClosed(None, None), {}, ""),  # the TCP connection dropped
        (
            ConnectionClosed(None, Close(CloseCode.MESSAGE_TOO_BIG, "")),
            {"message too big": 1},
            "message too big: web:1",
        ),
        (ConnectionClosed(None, Close(CloseCode.PROTOCOL_ERROR, "")), {}, ""),
        (RuntimeError("boom"), {}, "web:1: RuntimeError: boom"),
    ],
)
def test_however_a_connection_ends_its_puppet_is_freed_and_only_a_too_big_message_counts(
    make: Callable[..., WebSource], ending: BaseException, drops: dict[str, int], error: str
) -> None:
    """A close is no error; a close we sent for an oversized message is a drop named for the controller;
    anything else that breaks the connection is reported with its type, and never reaches the server."""
    src = make()

    async def scenario() -> None:
        page = _Page()
        task = await _open(src, page)
        page.feed(ending)
        await _end(task)
        assert src._slots == {} and src.viewers == 0 and not _others()

    _run(scenario)
    assert _events(src) == [("connect", "web:1"), ("disconnect", "web:1")]
    status = src.status()
    assert status.drop_reasons == drops and status.last_error == error


def test_a_page_gone_before_its_hello_frees_the_puppet(make: Callable[..., WebSource]) -> None:
    src = make()

    async def scenario() -> None:
        page = _Page()
        page.send_error = _closed_by_page(1001)
        src._loop = asyncio.get_running_loop()
        await asyncio.wait_for(src._connection(page), GUARD)
        assert src._slots == {} and src.viewers == 0

    _run(scenario)
    assert _events(src) == [("connect", "web:1"), ("disconnect", "web:1")]
    assert src.status().last_error == ""


def test_a_silent_phone_frees_its_puppet_before_its_connection_is_closed(make: Callable[..., WebSource]) -> None:
    """A frozen phone may take the whole close timeout to answer the close: its puppet (slot, page clock,
    the stick's disconnect) is let go first, and only once."""
    src = make(silent_after=0.05)

    async def scenario() -> None:
        page = _Page(on_close=lambda: (dict(src._slots), dict(src._clocks), src.status().connected))
        task = await _open(src, page)
        page.feed(_reading(t=5000.0))  # one reading, then nothing: recv waits past silent_after
        await _end(task)
        assert page.closed == [(4002, "silent for too long", ({}, {}, False))]

    _run(scenario)
    events = _events(src)
    assert events == [("connect", "web:1"), ("disconnect", "web:1")]
    status = src.status()
    assert status.drop_reasons == {"silent controller": 1} and status.last_error == "silent controller: web:1"
    assert status.packets == 1


# -- messages ---------------------------------------------------------------------------------------


def test_a_connection_queues_readings_answers_pings_and_counts_bad_messages(make: Callable[..., WebSource]) -> None:
    src = make(max_controllers=2)
    src._slots[1] = object()

    async def scenario() -> None:
        page = _Page()
        task = await _open(src, page)
        page.feed(_reading(t=2000.0, touch=True), "{oops", json.dumps({"ack": 7}), json.dumps({"ping": 42.5}))
        await page.until(lambda: len(page.sent) == 2)
        page.feed(_closed_by_page())
        await _end(task)
        assert page.sent == [json.dumps({"hello": "web:2"}), json.dumps({"pong": 42.5})]

    _run(scenario)
    items = src.drain()
    samples = [s for s in items if isinstance(s, PoseSample)]
    assert [s.source for s in samples] == ["web:2"] and samples[0].touch
    assert samples[0].time == 100.0 and dict(src.page_times) == {100.0: 2000.0}
    assert [i for i in items if isinstance(i, tuple)] == [("connect", "web:2"), ("disconnect", "web:2")]
    assert src.status().drop_reasons == {"malformed message": 1}


def test_a_phone_that_leaves_takes_its_page_clock_with_it(make: Callable[..., WebSource]) -> None:
    """The next phone on the same puppet starts its own clock estimate: with the last phone's offset
    (95 s) its reading would be stamped 100.5, half a second before it arrived."""
    clock = _Clock(100.0)
    src = make(clock=clock)

    async def scenario() -> None:
        first = _Page()
        task = await _open(src, first)
        first.feed(_reading(t=5000.0))  # arrives at 100 s: the page clock is 95 s behind
        await _settle()
        assert src._clocks.keys() == {"web:1"}
        first.feed(_closed_by_page())
        await _end(task)
        assert src._clocks == {}
        clock.now = 101.0
        second = _Page()
        task = await _open(src, second)
        second.feed(_reading(t=5500.0), _closed_by_page())  # 95.5 s behind: within a second of the old offset
        await _end(task)

    _run(scenario)
    times = [s.time for s in src.drain() if isinstance(s, PoseSample)]
    assert times == [100.0, 101.0]


# -- the scene stream -------------------------------------------------------------------------------


def _state(step: int) -> tuple[SceneState, RenderScene]:
    scene = RenderScene()
    scene.add_capsule([0.0, 0.5, 0.01 * step], [0.0, 1.0, 0.01 * step], 0.05)
    return quantise(scene, step, 0.0, CAM), scene


SNOW = Snowfall(np.array([[0.5, 3.0, -1.0], [1.0, 6.0, 2.0]]), np.array([0.1, 0.7]))


def test_the_page_gets_the_glb_then_deltas_and_never_more_than_it_has_not_acknowledged(
    make: Callable[..., WebSource],
) -> None:
    """The first message is the GLB of the newest state (its look, snowfall and step time); then each
    frame is the delta from the last one sent; at ``FRAMES_IN_FLIGHT`` unacknowledged frames nothing
    more goes; the ack of the oldest frees one, and the next frame is the newest state, not a backlog."""
    assert FRAMES_IN_FLIGHT == 2
    src = make()
    states = {step: _state(step) for step in range(1, 8)}
    dt = 1 / 30

    def publish(step: int) -> None:
        state, look = states[step]
        src.publish(state, look, SNOW, dt)

    async def scenario() -> None:
        page = _Page()
        task = await _open(src, page)
        publish(1)
        await page.until(lambda: len(page.sent) == 2)
        assert page.sent[1] == scene_glb(states[1][0], states[1][1], SNOW, dt)
        publish(1)  # the same step again (one frame in flight): nothing new to send
        await _settle()
        assert len(page.sent) == 2
        publish(2)
        await page.until(lambda: len(page.sent) == 3)
        assert page.sent[2] == encode_frame(states[1][0], states[2][0])
        for step in (3, 4):  # two frames in flight: these wait, and step 3 is replaced by step 4
            publish(step)
            await _settle()
        assert len(page.sent) == 3
        page.feed(json.dumps({"ack": 1}))  # the oldest frame arrived: one more may go, the newest
        await page.until(lambda: len(page.sent) == 4)
        assert page.sent[3] == encode_frame(states[2][0], states[4][0])
        publish(5)  # still two in flight (steps 2 and 4)
        await _settle()
        assert len(page.sent) == 4
        page.feed(json.dumps({"ack": 4}))
        await page.until(lambda: len(page.sent) == 5)
        assert page.sent[4] == encode_frame(states[4][0], states[5][0])
        publish(6)
        await page.until(lambda: len(page.sent) == 6)
        assert page.sent[5] == encode_frame(states[5][0], states[6][0])
        publish(7)  # steps 5 and 6 in flight
        await _settle()
        assert len(page.sent) == 6
        assert src.frames_sent == 5 and src.frame_bytes == sum(len(m) for m in page.sent[1:])
        page.feed(_closed_by_page())
        await _end(task)

    _run(scenario)


def test_every_page_is_woken_by_a_publish_and_a_page_that_went_away_gets_nothing(
    make: Callable[..., WebSource],
) -> None:
    src = make(max_controllers=2)

    async def scenario() -> None:
        one, two = _Page(), _Page()
        tasks = [await _open(src, one), await _open(src, two)]
        assert src.viewers == 2
        state, look = _state(1)
        src.publish(state, look)
        await one.until(lambda: len(one.sent) == 2)
        await two.until(lambda: len(two.sent) == 2)
        assert one.sent[1] == two.sent[1] == scene_glb(state, look)
        two.send_error = _closed_by_page(1001)
        src.publish(*_state(2))
        await one.until(lambda: len(one.sent) == 3)
        await _settle()
        assert len(two.sent) == 2 and src.frames_sent == 3
        for page, task in zip((one, two), tasks, strict=True):
            page.feed(_closed_by_page())
            await _end(task)

    _run(scenario)


def test_publishing_before_the_server_runs_or_after_it_stopped_only_keeps_the_state(
    make: Callable[..., WebSource],
) -> None:
    """The engine thread publishes whatever the server thread is doing: no loop yet, or a closed one.

    With no page watching nothing is coded; with one, the frame from the state before is (at publication).
    """
    src = make()
    state, look = _state(1)
    src.publish(state, look, SNOW, 0.5)
    first = src._latest
    assert first is not None and (first.state, first.look, first.snowfall, first.dt) == (state, look, SNOW, 0.5)
    assert first.since is None and first.frame is None
    loop = asyncio.new_event_loop()
    loop.close()
    src._loop = loop
    src._wakes.add(asyncio.Event())
    later, _ = _state(2)
    src.publish(later, look)
    latest = src._latest
    assert latest is not None and latest.state is later and latest.snowfall is None and latest.dt == 1 / 60
    assert latest.since is state and latest.frame is not None
    assert decode_frame(state, latest.frame).step == 2


# -- one message ------------------------------------------------------------------------------------


def test_the_rate_bucket_refills_with_time_and_a_whole_token_is_a_reading(make: Callable[..., WebSource]) -> None:
    """``bucket`` is ``[tokens, last time]``: it refills at ``max_rate`` a second up to ``max_rate``, a reading
    spends one, and one token (not less) is enough."""
    src = make(max_rate=10.0)
    bucket = [2.0, 100.0]
    assert src._handle(_reading(), "web:1", bucket, 100.05) is None
    assert bucket == pytest.approx([1.5, 100.05], abs=1e-12)
    assert src._handle(_reading(), "web:1", bucket, 100.05) is None
    assert bucket == pytest.approx([0.5, 100.05], abs=1e-12)
    assert src._handle(_reading(), "web:1", bucket, 100.05) is None  # half a token: dropped
    assert bucket == pytest.approx([0.5, 100.05], abs=1e-12)
    assert src.status().drop_reasons == {"rate limit": 1} and src.status().last_error == "rate limit: web:1"
    exact = [1.0, 100.0]
    assert src._handle(_reading(), "web:1", exact, 100.0) is None
    assert exact == [0.0, 100.0]
    full = [3.0, 100.0]
    src._handle(_reading(), "web:1", full, 200.0)  # a long pause refills to max_rate, not beyond
    assert full == [9.0, 200.0]
    samples = [s for s in src.drain() if isinstance(s, PoseSample)]
    assert len(samples) == 4 and src.status().drop_reasons == {"rate limit": 1}


def test_a_message_is_a_pong_an_ack_or_a_named_drop(make: Callable[..., WebSource]) -> None:
    src = make()
    assert src._handle(json.dumps({"ping": 3.25}), "web:1", [5.0, 100.0], 100.0) == '{"pong": 3.25}'
    assert src._handle('{"ack": 12}', "web:1", [5.0, 100.0], 100.0) == Ack(12)
    with pytest.raises(WebMessageError) as err:
        parse_message("[1, 2]")
    assert src._handle("[1, 2]", "web:2", [5.0, 100.0], 100.0) is None
    status = src.status()
    assert status.drop_reasons == {"malformed message": 1}
    assert status.last_error == f"malformed message: web:2: {err.value}"
    assert src.drain() == [] and not src.page_times


def test_each_controller_has_its_own_page_clock(make: Callable[..., WebSource]) -> None:
    """Two phones' clocks differ: web:2's reading (page clock 95.5 s behind) would be stamped 99.75 with
    web:1's offset (95 s); with its own it is stamped at its arrival."""
    src = make(max_controllers=2)
    src._handle(_reading(t=5000.0), "web:1", [5.0, 100.0], 100.0)
    src._handle(_reading(t=4750.0), "web:2", [5.0, 100.0], 100.25)
    samples = [s for s in src.drain() if isinstance(s, PoseSample)]
    assert [(s.source, s.time) for s in samples] == [("web:1", 100.0), ("web:2", 100.25)]
    assert dict(src.page_times) == {100.0: 5000.0, 100.25: 4750.0}


def test_the_page_times_keep_the_newest_4096(make: Callable[..., WebSource]) -> None:
    src = make()
    src.page_times.update((float(i), 0.0) for i in range(4096))
    src._handle(_reading(t=8000.0), "web:1", [5.0, 100.0], 5000.0)
    assert len(src.page_times) == 4096
    assert next(iter(src.page_times)) == 1.0 and src.page_times[5000.0] == 8000.0


# -- stopping ---------------------------------------------------------------------------------------


def test_stop_gives_up_on_a_stuck_server_thread_and_still_closes_the_port(
    make: Callable[..., WebSource], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Quitting the game never hangs on the web thread: ``stop`` waits ``timeout`` seconds for it (0.1 s
    here, the thread's own join limit), then closes the listening socket anyway. Passing ``None`` on to
    the join instead (a mutant) waits for ever."""
    src = make()
    release = threading.Event()
    monkeypatch.setattr(src, "_run", release.wait)  # a server thread that does not see `stopping`
    src.start()
    thread = src._thread
    assert thread is not None
    try:
        src.stop(0.1)
        assert thread.is_alive() and src._thread is None and src._sock.fileno() == -1
    finally:
        release.set()
        thread.join(GUARD)
    assert not thread.is_alive()


class _Thread:
    """Stands for the server thread: records how long ``stop`` waits for it."""

    def __init__(self) -> None:
        self.waits: list[float | None] = []

    def join(self, timeout: float | None = None) -> None:
        self.waits.append(timeout)


def test_stop_waits_as_long_as_every_source_does(
    make: Callable[..., WebSource], monkeypatch: pytest.MonkeyPatch
) -> None:
    """The hub stops every source the same way (``stop()``): the web source waits its base's default for
    the thread (read from ``PoseSource.stop``; a changed default of its own fails)."""
    src = make()
    thread = _Thread()
    monkeypatch.setattr(src, "_thread", thread)
    src.stop()
    assert thread.waits == [inspect.signature(PoseSource.stop).parameters["timeout"].default]
    assert src._thread is None and src._sock.fileno() == -1
