"""The web controller source: an HTTPS server for the page and a WebSocket for its readings.

``--source web`` starts it. One device thread runs an asyncio loop (``websockets``)
that only fills the source's queue, like every other device thread; the hub drains it
once per step, so web readings are recorded and replayed like any source's.

Safety on a LAN:

- binds ``127.0.0.1`` unless told ``0.0.0.0`` (``--web-host``), like OSC;
- a session token (random, new every start) is part of the URL the QR code carries;
  the page and the WebSocket answer 403 without it, so someone else on the Wi-Fi
  cannot drive the game;
- one controller per puppet: ``max_controllers`` connections hold slots ``web:1`` …;
  another phone is told every puppet is taken (``{"taken": true}``) and closed;
- a controller silent for ``silent_after`` seconds (2 s; the page sends at least four
  readings and a ping a second) is a frozen phone: its slot is freed at once (the stick
  lets go) and its connection closed, so the next phone with the token gets the puppet
  instead of waiting out the WebSocket's keep-alive (22.8 s before);
- every message passes :func:`input.web.protocol.parse_message`; malformed ones, and
  readings beyond ``max_rate`` per second per connection (a token bucket), are counted
  with their reason and dropped, never raised. A message over 64 KiB closes the
  connection in the WebSocket layer before it is read (counted as "message too big").

The phone is also the viewport (:mod:`input.web.viewport`): after every step the
engine thread hands :meth:`WebSource.publish` the quantised scene; each connection
sends its page the scene as a GLB once (:mod:`input.web.scene_glb`), then a frame
delta-coded against what *that* page last got (:mod:`input.web.scene_stream`). The frame
from the previous step, which every page that keeps up holds, is coded once on the engine
thread at publication, so the server thread, woken, only writes it. A
connection never queues: it holds only the newest state, and sends while fewer than
:data:`FRAMES_IN_FLIGHT` frames wait for the page's ``{"ack": step}``, so a slow phone
(or Wi-Fi) gets fewer frames, each the latest, rather than a growing backlog. The page
reads the socket in a worker of its own (``page/stream_worker.js``) and acknowledges a
frame as soon as it is decoded there, so the acknowledgements pace the network and the
phone, not the page's drawing.

:attr:`WebSource.page_times` remembers, for the latest readings, the page's clock at
the sensor event, keyed by the sample's receive time: the latency bench reads it.
"""

from __future__ import annotations

import asyncio
import hmac
import json
import secrets
import socket
import time
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass, field
from importlib import resources
from typing import Any
from urllib.parse import parse_qs, urlsplit

from websockets.exceptions import ConnectionClosed
from websockets.frames import CloseCode

from engine.render.snowfall import Snowfall
from input.source import PoseSource
from input.web.cert import WebCertificate, load_or_create
from input.web.protocol import Ack, ControllerMessage, PageClock, Ping, WebMessageError, parse_message, to_sample_fields
from input.web.scene_glb import scene_glb
from input.web.scene_stream import SceneState, encode_frame

__all__ = ["WebSource", "DEFAULT_WEB_PORT", "PAGE_FILES", "FRAMES_IN_FLIGHT"]

DEFAULT_WEB_PORT = 8443
_JS = "text/javascript; charset=utf-8"
#: The page's files and their content types (served from the package, no build step).
PAGE_FILES = {
    "/": ("index.html", "text/html; charset=utf-8"),
    "/index.html": ("index.html", "text/html; charset=utf-8"),
    "/app.js": ("app.js", _JS),
    "/stream.js": ("stream.js", _JS),
    "/stream_worker.js": ("stream_worker.js", _JS),
    "/render_worker.js": ("render_worker.js", _JS),
    "/render.js": ("render.js", _JS),
    "/placement.js": ("placement.js", _JS),
    "/style.css": ("style.css", "text/css; charset=utf-8"),
}
#: Scene frames a connection may have sent and not yet had acknowledged.
FRAMES_IN_FLIGHT = 2
_TOKEN_PAGES = {"/", "/index.html", "/ws"}
_FRAME_LIMIT = 64 * 1024  # bytes: a larger WebSocket message closes the connection unread


@dataclass(frozen=True)
class _Published:
    """The newest scene as the engine thread handed it over, with the frame from the state published before.

    ``frame`` takes a page holding ``since`` (the previous publication: what a page that keeps
    up holds) to ``state``; it is coded once, on the engine thread at publication, for every
    such page, so the server thread only writes it. A page holding anything else (it fell
    behind, or has just had the GLB) gets a frame coded against what it holds, there.
    """

    state: SceneState
    look: Any
    snowfall: Snowfall | None
    dt: float
    since: SceneState | None
    frame: bytes | None


@dataclass
class _Acks:
    """What one page has acknowledged: the newest scene step it has, and a wake for its sender."""

    step: int = -1
    arrived: asyncio.Event = field(default_factory=asyncio.Event)


def _page(name: str) -> bytes:
    return resources.files("input.web").joinpath("page", name).read_bytes()


class WebSource(PoseSource):
    """Phones' browsers as MotionSticks (see the module docstring).

    Args:
        host: bind address (``0.0.0.0`` for phones on the LAN).
        port: TCP port; 0 picks a free one (read :attr:`port`).
        max_controllers: phones that may hold a puppet at once.
        max_rate: readings per second accepted per connection (a burst of one second).
        silent_after: seconds without a message after which a controller's puppet is freed.
        certificate: the TLS certificate (default: the user's, made on first use).
        token: the session token (default: a new random one).
        clock: the seconds the rate limit and the page clocks are measured in (monotonic time;
            a test gives a clock it moves itself).

    Raises:
        ValueError: ``max_controllers`` below 1 or a port outside 0..65535.
        OSError: the port cannot be bound or the certificate folder cannot be written.
    """

    def __init__(
        self,
        host: str = "127.0.0.1",
        port: int = DEFAULT_WEB_PORT,
        max_controllers: int = 1,
        max_rate: float = 240.0,
        certificate: WebCertificate | None = None,
        token: str | None = None,
        capacity: int = 256,
        silent_after: float = 2.0,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        if max_controllers < 1:
            raise ValueError(f"max_controllers must be at least 1, not {max_controllers}")
        if not 0 <= port <= 65535:
            raise ValueError(f"web port must be 0..65535, not {port}")
        super().__init__(f"web {host}:{port}", capacity)
        from input.pairing import lan_addresses

        self.host = host
        self.max_controllers = max_controllers
        self.max_rate = max_rate
        self.silent_after = silent_after
        self.clock = clock
        self.certificate = certificate or load_or_create(lan_addresses())
        # Made here, not in the server thread: a certificate that cannot serve is an error at
        # start (one line), never a dead thread while the game runs on without input.
        self._ssl = self.certificate.ssl_context()
        self.token = token or secrets.token_urlsafe(16)
        # IPPROTO_TCP, not the default 0: asyncio turns Nagle's algorithm off (TCP_NODELAY) only on
        # accepted sockets whose protocol says TCP, and they inherit it from this one. With Nagle on, a
        # frame written while the pong of the page's once-a-second ping was still unacknowledged waited
        # for the page's delayed ACK: every second, two steps reached the page 20-45 ms late (bench
        # phone-view, drawing paused: received p99 32 ms with Nagle, 9 ms without the pings).
        self._sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM, socket.IPPROTO_TCP)
        self._sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            self._sock.bind((host, port))
            self._sock.listen(16)
        except OSError:
            self._sock.close()
            raise
        self._sock.setblocking(False)
        self.port: int = self._sock.getsockname()[1]
        self.name = self._status.name = f"web {host}:{self.port}"
        self._slots: dict[int, Any] = {}
        self.page_times: OrderedDict[float, float] = OrderedDict()
        self._clocks: dict[str, PageClock] = {}  # per controller: its page's event times on our clock
        self.refused = 0
        self._loop: asyncio.AbstractEventLoop | None = None
        self._latest: _Published | None = None
        self._wakes: set[asyncio.Event] = set()
        self.frames_sent = 0
        self.frame_bytes = 0

    @property
    def viewers(self) -> int:
        """Pages connected to watch the scene (each controller's page is one)."""
        return len(self._wakes)

    def publish(self, state: SceneState, look: Any, snowfall: Snowfall | None = None, dt: float = 1 / 60) -> None:
        """Hand the pages the newest scene (engine thread); ``look`` is the scene whose ground,
        sun and sky the GLB carries, with ``snowfall`` (moved by the page: step × ``dt`` seconds).
        Older states not yet sent are simply replaced. While a page watches, the frame from the
        previous state is coded here, so the server thread, woken, only has to write it."""
        before = self._latest
        wakes = bool(self._wakes)
        frame = encode_frame(before.state, state) if wakes and before is not None else None
        self._latest = _Published(state, look, snowfall, dt, before.state if before is not None else None, frame)
        loop = self._loop
        if loop is not None and wakes:
            try:
                loop.call_soon_threadsafe(self._wake_all)
            except RuntimeError:  # the server loop has just closed
                pass

    def _wake_all(self) -> None:
        for wake in self._wakes:
            wake.set()

    def url(self, address: str | None = None) -> str:
        """The controller page's address with the session token (what the QR code carries)."""
        return f"https://{address or self.host}:{self.port}/?t={self.token}"

    def stop(self, timeout: float = 2.0) -> None:
        """Stop the server thread and close the listening socket."""
        super().stop(timeout)
        self._sock.close()

    # -- the server thread -------------------------------------------------------------
    def _run(self) -> None:
        asyncio.run(self._serve())

    async def _serve(self) -> None:
        from websockets.asyncio.server import serve

        self._loop = asyncio.get_running_loop()
        async with serve(
            self._connection,
            sock=self._sock,
            ssl=self._ssl,
            process_request=self._http,
            max_size=_FRAME_LIMIT,
            max_queue=32,
            ping_interval=5,
            ping_timeout=10,
            close_timeout=1,
            server_header="PuppetPhone",
        ):
            while not self.stopping.is_set():
                await asyncio.sleep(0.05)

    def _authorised(self, path: str) -> bool:
        given = parse_qs(urlsplit(path).query).get("t", [""])[0]
        return hmac.compare_digest(given.encode(), self.token.encode())

    def _http(self, connection: Any, request: Any) -> Any:
        """Serve the page's files; let ``/ws`` with the token through to the WebSocket."""
        from websockets.datastructures import Headers
        from websockets.http11 import Response

        route = urlsplit(request.path).path
        if route in _TOKEN_PAGES and not self._authorised(request.path):
            self.refused += 1
            self.drop("wrong session token", route)
            body = b"This controller link is not for the running game: scan its QR code again.\n"
            return Response(
                403,
                "Forbidden",
                Headers([("Content-Type", "text/plain; charset=utf-8"), ("Content-Length", str(len(body)))]),
                body,
            )
        if route == "/ws":
            return None
        if route not in PAGE_FILES:
            return connection.respond(404, "Not found\n")
        name, ctype = PAGE_FILES[route]
        body = _page(name)
        return Response(
            200,
            "OK",
            Headers([("Content-Type", ctype), ("Content-Length", str(len(body))), ("Cache-Control", "no-store")]),
            body,
        )

    async def _connection(self, ws: Any) -> None:
        slot = next((i for i in range(1, self.max_controllers + 1) if i not in self._slots), None)
        if slot is None:
            self.drop("every puppet taken", str(ws.remote_address))
            await ws.send(json.dumps({"taken": True}))
            await ws.close(4001, "every puppet has a controller")
            return
        controller = f"web:{slot}"
        self._slots[slot] = ws
        self.connected(controller)
        bucket = [self.max_rate, self.clock()]
        acked = _Acks()
        wake = asyncio.Event()
        sender = None
        try:
            await ws.send(json.dumps({"hello": controller}))
            self._wakes.add(wake)
            sender = asyncio.create_task(self._stream(ws, wake, acked))
            while True:
                try:
                    message = await asyncio.wait_for(ws.recv(), self.silent_after)
                except TimeoutError:  # a frozen phone: free its puppet now, then close
                    self.drop("silent controller", controller)
                    self._release(slot, controller)
                    await ws.close(4002, "silent for too long")
                    return
                reply = self._handle(message, controller, bucket, self.clock())
                if isinstance(reply, Ack):
                    acked.step = max(acked.step, reply.step)
                    acked.arrived.set()
                elif reply is not None:
                    await ws.send(reply)
        except ConnectionClosed as exc:
            if exc.sent is not None and exc.sent.code == CloseCode.MESSAGE_TOO_BIG:
                self.drop("message too big", controller)
        except Exception as exc:  # a broken connection ends this controller, never the server
            self.error(f"{controller}: {type(exc).__name__}: {exc}")
        finally:
            self._wakes.discard(wake)
            if sender is not None:
                sender.cancel()
            self._release(slot, controller)

    async def _stream(self, ws: Any, wake: asyncio.Event, acked: _Acks) -> None:
        """Send one page the scene: the GLB once, then the newest state while few frames are unacknowledged."""
        sent: list[int] = []
        base: SceneState | None = None
        while True:
            await wake.wait()
            wake.clear()
            while sent and sent[0] <= acked.step:
                sent.pop(0)
            if len(sent) >= FRAMES_IN_FLIGHT:
                acked.arrived.clear()
                await acked.arrived.wait()
                wake.set()  # look again: the newest state is still there to send
                continue
            latest = self._latest
            if latest is None or (base is not None and latest.state.step == base.step):
                continue
            state = latest.state
            if base is None:
                data = scene_glb(state, latest.look, latest.snowfall, latest.dt)
            elif latest.frame is not None and latest.since is base:
                data = latest.frame  # coded on the engine thread at publication
            else:
                data = encode_frame(base, state)
            try:
                await ws.send(data)
            except ConnectionClosed:
                return  # the reading loop sees the close and releases the slot
            base = state
            sent.append(state.step)
            self.frames_sent += 1
            self.frame_bytes += len(data)

    def _release(self, slot: int, controller: str) -> None:
        """Free ``slot`` (once) and tell the hub its controller is gone."""
        self._clocks.pop(controller, None)
        if self._slots.pop(slot, None) is not None:
            self.disconnected(controller)

    def _handle(self, message: str | bytes, controller: str, bucket: list[float], now: float) -> str | Ack | None:
        """One message of one connection: queue its sample, answer a ping, pass an ack on, or count and drop it."""
        tokens = min(self.max_rate, bucket[0] + (now - bucket[1]) * self.max_rate)
        bucket[1] = now
        if tokens < 1.0:
            bucket[0] = tokens
            self.drop("rate limit", controller)
            return None
        bucket[0] = tokens - 1.0
        try:
            msg = parse_message(message)
        except WebMessageError as exc:
            self.drop("malformed message", f"{controller}: {exc}")
            return None
        if isinstance(msg, Ping):
            return json.dumps({"pong": msg.t})
        if isinstance(msg, Ack):
            return msg
        assert isinstance(msg, ControllerMessage)
        clock = self._clocks.setdefault(controller, PageClock())
        sample = self.offer(**to_sample_fields(msg, controller, clock.stamp(msg.t, now)))
        if sample is not None:
            self.page_times[sample.time] = msg.t
            while len(self.page_times) > 4096:
                self.page_times.popitem(last=False)
        return None
