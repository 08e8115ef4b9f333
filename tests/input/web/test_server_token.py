"""The web server's request gate without a socket: ``WebSource._http`` answers a request object directly.

``test_token.py`` proves the same rules end to end over TLS (about 2 s a test); these take milliseconds,
so the mutation run (docs/mutation.md) can afford them for every mutant of the token code. Each rule was
shown to fail by its mutmut mutant (named in docs/mutation.md, fifth round): the token compared by prefix
(``self.token.startswith(given)``) or as ``given in token``, the query's second ``t`` read, ``/index.html``
or ``/ws`` left out of the guarded pages, the 403 served as 200 or with a wrong length, the refusal not
counted, the page served without its length or ``no-store``, the URL without the token.
"""

from __future__ import annotations

import contextlib
import gc
import inspect
import ipaddress
import json
import socket
import time
import warnings
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from cryptography import x509

from input.sample import PoseSample
from input.web.cert import WebCertificate, load_or_create
from input.web.server import DEFAULT_WEB_PORT, PAGE_FILES, WebSource

TOKEN = "s3cr3t-Session-Token"
GUARDED = ("/", "/index.html", "/ws")


@dataclass
class _Request:
    path: str


class _Connection:
    """Stands for websockets' server connection: records what ``respond`` was asked."""

    def __init__(self) -> None:
        self.responded: list[tuple[int, str]] = []

    def respond(self, status: int, text: str) -> tuple[str, int, str]:
        self.responded.append((status, text))
        return ("respond", status, text)


@pytest.fixture(scope="module")
def certificate(tmp_path_factory: pytest.TempPathFactory) -> WebCertificate:
    return load_or_create(["192.168.1.20"], tmp_path_factory.mktemp("web"))


@pytest.fixture
def source(certificate: WebCertificate) -> Iterator[WebSource]:
    src = WebSource(port=0, certificate=certificate, token=TOKEN)
    yield src
    src.stop()


def _http(src: WebSource, path: str) -> Any:
    return src._http(_Connection(), _Request(path))


def _wrong_tokens() -> list[str]:
    """A prefix, a longer token, a suffix, one character changed, the case changed, empty."""
    return ["", TOKEN[:-1], TOKEN[:1], TOKEN + "x", TOKEN[1:], "S" + TOKEN[1:], TOKEN.upper(), TOKEN[2:-2]]


def _is_refusal(response: Any) -> bool:
    body = b"This controller link is not for the running game: scan its QR code again.\n"
    assert response is not None, "let through"
    assert not isinstance(response, tuple), "answered as a missing file"
    assert response.status_code == 403 and response.reason_phrase == "Forbidden"
    assert response.body == body
    assert response.headers["Content-Type"] == "text/plain; charset=utf-8"
    assert response.headers["Content-Length"] == str(len(body))
    return True


@pytest.mark.parametrize("route", GUARDED)
def test_every_page_that_opens_a_controller_refuses_a_wrong_token(source: WebSource, route: str) -> None:
    """A prefix of the token, the token with more after it, or none at all are all refused, and counted."""
    paths = [route, f"{route}?x=1"] + [f"{route}?t={wrong}" for wrong in _wrong_tokens()]
    for n, path in enumerate(paths, start=1):
        assert _is_refusal(_http(source, path)), path
        assert source.refused == n
        status = source.status()
        assert status.drop_reasons == {"wrong session token": n}
        assert status.last_error == f"wrong session token: {route}"


@pytest.mark.parametrize("route", ["/", "/index.html"])
def test_the_page_is_served_with_the_exact_token(source: WebSource, route: str) -> None:
    response = _http(source, f"{route}?t={TOKEN}")
    assert response.status_code == 200 and response.reason_phrase == "OK"
    page = (Path(__file__).parents[3] / "input" / "web" / "page" / "index.html").read_bytes()
    assert response.body == page
    assert response.headers["Content-Type"] == "text/html; charset=utf-8"
    assert response.headers["Content-Length"] == str(len(page))
    assert response.headers["Cache-Control"] == "no-store"
    assert source.refused == 0 and source.status().dropped == 0


def test_the_websocket_is_let_through_with_the_exact_token(source: WebSource) -> None:
    assert _http(source, f"/ws?t={TOKEN}") is None
    assert _http(source, f"/ws?v=2&t={TOKEN}&w=3") is None
    assert source.refused == 0


def test_only_the_first_token_in_the_query_counts(source: WebSource) -> None:
    """``?t=right&t=wrong`` is let through and ``?t=wrong&t=right`` is not: one reading of the query."""
    assert _http(source, f"/ws?t={TOKEN}&t=guess") is None
    assert _is_refusal(_http(source, f"/ws?t=guess&t={TOKEN}"))


def test_a_token_in_the_fragment_or_under_another_key_is_not_the_token(source: WebSource) -> None:
    assert _is_refusal(_http(source, f"/ws#t={TOKEN}"))
    assert _is_refusal(_http(source, f"/ws?s={TOKEN}"))


def test_static_files_need_no_token_and_unknown_paths_are_404(source: WebSource) -> None:
    folder = Path(__file__).parents[3] / "input" / "web" / "page"
    for route, (name, ctype) in PAGE_FILES.items():
        if route in GUARDED:
            continue
        response = _http(source, f"{route}?t=guess")
        assert response.status_code == 200, route
        assert response.body == (folder / name).read_bytes()
        assert response.headers["Content-Type"] == ctype
        assert response.headers["Content-Length"] == str(len(response.body))
        assert response.headers["Cache-Control"] == "no-store"
    connection = _Connection()
    assert source._http(connection, _Request(f"/secret.txt?t={TOKEN}")) == ("respond", 404, "Not found\n")
    assert source._http(connection, _Request("/index.htm")) == ("respond", 404, "Not found\n")
    assert connection.responded == [(404, "Not found\n"), (404, "Not found\n")]
    assert source.refused == 0


def test_the_link_carries_the_token(source: WebSource) -> None:
    assert source.url() == f"https://127.0.0.1:{source.port}/?t={TOKEN}"
    assert source.url("192.168.1.20") == f"https://192.168.1.20:{source.port}/?t={TOKEN}"
    assert _http(source, source.url().split(str(source.port), 1)[1]).status_code == 200


def test_a_session_without_a_given_token_gets_a_new_random_one(certificate: WebCertificate) -> None:
    """128 random bits, URL-safe, new every start."""
    tokens = []
    for _ in range(2):
        src = WebSource(port=0, certificate=certificate)
        tokens.append(src.token)
        assert _http(src, f"/?t={src.token}").status_code == 200
        src.stop()
    assert tokens[0] != tokens[1]
    for token in tokens:
        assert len(token) == 22 and all(c.isalnum() or c in "-_" for c in token)


def test_the_source_starts_bound_and_counting_nothing(source: WebSource) -> None:
    assert source.port > 0 and source.host == "127.0.0.1"
    assert source.name == source.status().name == f"web 127.0.0.1:{source.port}"
    assert source.refused == 0 and source.frames_sent == 0 and source.frame_bytes == 0
    assert source.viewers == 0 and not source.page_times
    assert source.max_controllers == 1 and source.max_rate == 240.0 and source.silent_after == 2.0
    listening = socket.create_connection(("127.0.0.1", source.port), timeout=5)
    listening.close()


def test_the_documented_defaults() -> None:
    params = inspect.signature(WebSource).parameters
    assert params["host"].default == "127.0.0.1"
    assert params["port"].default == DEFAULT_WEB_PORT == 8443
    assert params["max_controllers"].default == 1
    assert params["capacity"].default == 256
    assert params["silent_after"].default == 2.0


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"max_controllers": 0}, "max_controllers must be at least 1, not 0"),
        ({"port": -1}, "web port must be 0..65535, not -1"),
        ({"port": 65536}, "web port must be 0..65535, not 65536"),
    ],
)
def test_bad_settings_are_refused_before_binding(
    certificate: WebCertificate, kwargs: dict[str, int], message: str
) -> None:
    with pytest.raises(ValueError) as err:
        WebSource(**{"port": 0, "certificate": certificate, **kwargs})
    assert str(err.value) == message


def test_one_controller_and_port_65535_are_valid_settings(certificate: WebCertificate) -> None:
    """The limits are inclusive: one controller is allowed, and the highest port is a port."""
    src = WebSource(port=0, certificate=certificate, max_controllers=1)
    assert src.max_controllers == 1
    src.stop()
    taken = socket.socket()  # held here (or by someone else), so the bind fails: no fixed port is served
    try:
        with contextlib.suppress(OSError):
            taken.bind(("127.0.0.1", 65535))
        with pytest.raises(OSError):  # got past the range check to the bind
            WebSource(port=65535, certificate=certificate)
    finally:
        taken.close()


def test_a_port_that_cannot_be_bound_leaves_no_socket_open(certificate: WebCertificate) -> None:
    first = WebSource(port=0, certificate=certificate)
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            with pytest.raises(OSError, match="Address already in use"):
                WebSource(port=first.port, certificate=certificate)
            gc.collect()
        assert not [w for w in caught if issubclass(w.category, ResourceWarning)]
    finally:
        first.stop()


def _fill(src: WebSource, n: int) -> None:
    sample = PoseSample(time=0.0, source="web:1", orientation=np.array([1.0, 0.0, 0.0, 0.0]))
    for _ in range(n):
        src.push(sample)


def test_the_queue_holds_capacity_items(certificate: WebCertificate) -> None:
    """A queue of 256 by default, ``capacity`` when given; beyond it the oldest go and are counted."""
    for capacity, kwargs in ((256, {}), (4, {"capacity": 4})):
        src = WebSource(port=0, certificate=certificate, **kwargs)  # type: ignore[arg-type]  # capacity: an int
        _fill(src, capacity + 1)
        assert src.status().drop_reasons == {"queue full": 1} and len(src.drain()) == capacity
        src.stop()


def test_the_given_certificate_and_clock_are_the_ones_used(certificate: WebCertificate) -> None:
    def clock() -> float:
        return 12.5

    src = WebSource(port=0, certificate=certificate, clock=clock)
    assert src.certificate is certificate and src.clock is clock
    src.stop()
    src = WebSource(port=0, certificate=certificate)
    assert src.clock is time.monotonic
    src.stop()


def test_without_a_certificate_one_is_made_for_the_lan_addresses(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The user's certificate, made in ``$XDG_DATA_HOME`` on first use, names this machine's LAN address."""
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path))
    monkeypatch.setattr("input.pairing.lan_addresses", lambda: ["192.168.1.77"])
    src = WebSource(port=0)
    src.stop()
    assert src.certificate.cert_path == tmp_path / "puppetphone" / "web" / "cert.pem"
    cert = x509.load_pem_x509_certificate(src.certificate.cert_path.read_bytes())
    alt = cert.extensions.get_extension_for_class(x509.SubjectAlternativeName).value
    assert ipaddress.ip_address("192.168.1.77") in alt.get_values_for_type(x509.IPAddress)


def test_a_reading_is_queued_with_its_page_time(source: WebSource) -> None:
    """What a connection does with one reading: a sample for its controller, the page's clock remembered."""
    reading = {"seq": 0, "t": 1.5, "kind": "orientation", "o": [0.0, 10.0, 0.0], "touch": False}
    assert source._handle(json.dumps(reading), "web:1", [240.0, 3.0], 3.0) is None
    (sample,) = source.drain()
    assert isinstance(sample, PoseSample) and sample.source == "web:1"
    assert dict(source.page_times) == {sample.time: 1.5}


@pytest.mark.parametrize("token", ["XXXX", "t", "None"])
def test_a_request_without_a_token_matches_no_session_token(certificate: WebCertificate, token: str) -> None:
    """Whatever the session token is (any text the caller chose), leaving ``t`` out never equals it."""
    src = WebSource(port=0, certificate=certificate, token=token)
    try:
        for route in GUARDED:
            assert _is_refusal(_http(src, route)) and _is_refusal(_http(src, f"{route}?x={token}"))
        assert _http(src, f"/ws?t={token}") is None
    finally:
        src.stop()
