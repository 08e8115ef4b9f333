"""The web controller server on loopback: page and token, one controller per puppet, bad input counted."""

from __future__ import annotations

import json
import os
import socket
import ssl
import stat
import time
from urllib.error import HTTPError
from urllib.request import urlopen

import pytest
from websockets.exceptions import ConnectionClosed, InvalidStatus
from websockets.sync.client import connect

from input.hub import InputHub
from input.sample import PoseSample
from input.web.cert import fingerprint, load_or_create
from input.web.server import WebSource

READING = {"seq": 0, "t": 0.0, "kind": "orientation", "o": [0.0, 10.0, 0.0], "touch": False}


@pytest.fixture
def certificate(tmp_path):
    return load_or_create(["192.168.1.20"], tmp_path / "web")


@pytest.fixture
def source(certificate):
    src = WebSource(port=0, certificate=certificate, max_rate=100.0).start()
    yield src
    src.stop()


def _tls() -> ssl.SSLContext:
    ctx = ssl.create_default_context()
    ctx.check_hostname = False
    ctx.verify_mode = ssl.CERT_NONE  # the test trusts the certificate by its fingerprint instead
    return ctx


def _ws(src: WebSource, token: str | None = None):  # type: ignore[no-untyped-def]
    return connect(f"wss://127.0.0.1:{src.port}/ws?t={token or src.token}", ssl=_tls(), open_timeout=10)


def _wait(predicate, timeout: float = 5.0) -> None:  # type: ignore[no-untyped-def]
    end = time.monotonic() + timeout
    while not predicate():
        assert time.monotonic() < end, "timed out"
        time.sleep(0.01)


def test_certificate_is_made_once_kept_private_and_served(tmp_path, certificate, source):
    again = load_or_create([], tmp_path / "web")
    assert not again.created and certificate.created and again.fingerprint == certificate.fingerprint
    assert stat.S_IMODE(os.stat(certificate.key_path).st_mode) == 0o600
    with (
        socket.create_connection(("127.0.0.1", source.port), timeout=10) as raw,
        _tls().wrap_socket(raw, server_hostname="localhost") as tls,
    ):
        served = tls.getpeercert(binary_form=True)
    assert fingerprint(served) == certificate.fingerprint


def test_broken_certificate_files_are_replaced(tmp_path, certificate):
    certificate.cert_path.write_text("garbage")
    fresh = load_or_create([], tmp_path / "web")
    assert fresh.created and fresh.fingerprint != certificate.fingerprint


def test_page_needs_the_session_token(source):
    with urlopen(source.url(), context=_tls(), timeout=10) as r:
        page = r.read().decode()
    assert "touch" in page and "app.js" in page
    with urlopen(f"https://127.0.0.1:{source.port}/app.js", context=_tls(), timeout=10) as script:
        assert script.headers["Content-Type"].startswith("text/javascript")
    for bad in (f"https://127.0.0.1:{source.port}/", f"https://127.0.0.1:{source.port}/?t=guess"):
        with pytest.raises(HTTPError) as err:
            urlopen(bad, context=_tls(), timeout=10)
        err.value.close()
        assert err.value.code == 403
    with pytest.raises(InvalidStatus), _ws(source, "guess"):
        pass
    assert source.status().drop_reasons["wrong session token"] == 3
    assert source.host == "127.0.0.1"  # loopback unless told otherwise


def test_one_controller_per_puppet_and_readings_reach_the_hub(source):
    hub = InputHub([source])
    with _ws(source) as phone:
        assert json.loads(phone.recv(timeout=5)) == {"hello": "web:1"}
        with _ws(source) as other:
            assert json.loads(other.recv(timeout=5)) == {"taken": True}
            with pytest.raises(ConnectionClosed):
                other.recv(timeout=5)
        phone.send(json.dumps({**READING, "touch": True}))
        phone.send(json.dumps({"ping": 42.0}))
        assert json.loads(phone.recv(timeout=5)) == {"pong": 42.0}
        frame = hub.drain(0)
        assert frame.has_event("connect", "web:1") and frame.has_event("touch_down", "web:1")
        assert [s.source for s in frame.samples] == ["web:1"]
        assert source.page_times[frame.samples[0].time] == 0.0
    _wait(lambda: source.status().connected is False)
    assert hub.drain(1).has_event("disconnect", "web:1")
    with _ws(source) as again:  # the slot is free again
        assert json.loads(again.recv(timeout=5)) == {"hello": "web:1"}


class _HandClock:
    """Seconds that pass only when the test says so: the rate limit is counted, not timed."""

    def __init__(self) -> None:
        self.now = 1000.0

    def __call__(self) -> float:
        return self.now


def test_malformed_and_flooding_messages_are_counted_and_dropped(certificate):
    """Broken on purpose: the bucket never spent (``bucket[0] = tokens``) lets all 400 through; a
    bucket that does not refill with time keeps the ping out."""
    clock = _HandClock()
    source = WebSource(port=0, certificate=certificate, max_rate=100.0, clock=clock).start()
    try:
        with _ws(source) as phone:
            phone.recv(timeout=5)
            phone.send(b"\x00binary")
            phone.send("{oops")
            phone.send(json.dumps({**READING, "o": [0, float("inf"), 0]}).replace("Infinity", "1e999"))
            for i in range(400):  # far past the 100/s bucket, all within the same instant
                phone.send(json.dumps({**READING, "seq": i}))
            _wait(lambda: source.status().packets + source.status().drop_reasons.get("rate limit", 0) == 400)
            clock.now += 0.1  # the bucket refills by 10: the ping is read
            phone.send(json.dumps({"ping": 1.0}))
            phone.recv(timeout=5)  # the connection is alive and answers
        status = source.status()
        assert status.drop_reasons["malformed message"] == 3
        # a full bucket of 100: 3 spent by the malformed messages, 97 readings, the rest dropped
        assert status.drop_reasons["rate limit"] == 303
        queued = [s for s in source.drain() if isinstance(s, PoseSample)]
        assert len(queued) == 97
        with _ws(source) as phone:  # a huge message ends that connection, and only that
            phone.recv(timeout=5)
            phone.send("x" * 100_000)
            with pytest.raises(ConnectionClosed):
                phone.recv(timeout=5)
        _wait(lambda: source.status().drop_reasons.get("message too big") == 1)
        with _ws(source) as phone:
            assert json.loads(phone.recv(timeout=5)) == {"hello": "web:1"}
    finally:
        source.stop()


def test_the_link_names_lan_addresses_when_bound_to_all(certificate):
    from input.pairing import lan_addresses
    from input.web.pairing import web_link

    src = WebSource(host="0.0.0.0", port=0, certificate=certificate)
    try:
        link = web_link(src)
    finally:
        src.stop()
    lan = lan_addresses()
    if not lan:
        pytest.skip("this machine has no LAN address")
    assert link.urls == [f"https://{a}:{src.port}/?t={src.token}" for a in lan]
    assert not link.loopback_only and "--web-host 0.0.0.0" not in "\n".join(link.lines())
    assert link.fingerprint == certificate.fingerprint


def test_a_key_that_does_not_belong_to_the_certificate_is_replaced_with_a_line(tmp_path, certificate, capsys):
    other = load_or_create([], tmp_path / "other")
    certificate.key_path.write_bytes(other.key_path.read_bytes())  # the key replaced, the certificate kept
    fresh = load_or_create([], tmp_path / "web")
    assert fresh.created and fresh.fingerprint not in (certificate.fingerprint, other.fingerprint)
    assert "does not belong to the certificate" in capsys.readouterr().err
    src = WebSource(port=0, certificate=fresh).start()  # and it serves
    try:
        with _ws(src) as phone:
            assert json.loads(phone.recv(timeout=5)) == {"hello": "web:1"}
    finally:
        src.stop()


def test_a_certificate_that_cannot_serve_is_an_error_at_start_not_a_dead_thread(tmp_path, certificate):
    from dataclasses import replace

    broken = replace(certificate, key_path=tmp_path / "missing.pem")
    with pytest.raises(OSError):
        WebSource(port=0, certificate=broken)


def test_a_frozen_phone_frees_its_puppet_for_the_next(certificate):
    src = WebSource(port=0, certificate=certificate, silent_after=0.3).start()
    try:
        with _ws(src) as frozen:
            assert json.loads(frozen.recv(timeout=5)) == {"hello": "web:1"}
            frozen.send(json.dumps(READING))
            _wait(lambda: src.status().drop_reasons.get("silent controller") == 1)  # then nothing more from it
            with _ws(src) as fresh:
                assert json.loads(fresh.recv(timeout=5)) == {"hello": "web:1"}  # not {"taken": true}
    finally:
        src.stop()
