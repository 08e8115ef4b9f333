"""The web controller's session token: every page that opens a controller needs the whole, exact token.

Shown to fail when broken: ``/index.html`` served without the token (dropped from ``_TOKEN_PAGES``),
a token *prefix* accepted (``_authorised`` made ``self.token.startswith(given)``), a longer token
accepted (``given.startswith(self.token)``), an empty ``?t=`` accepted.
"""

from __future__ import annotations

import ssl
from urllib.error import HTTPError
from urllib.request import urlopen

import pytest
from websockets.exceptions import InvalidStatus
from websockets.sync.client import connect

from input.web.cert import load_or_create
from input.web.server import WebSource


@pytest.fixture(scope="module")
def certificate(tmp_path_factory):
    return load_or_create(["192.168.1.20"], tmp_path_factory.mktemp("web"))


@pytest.fixture
def source(certificate):
    """A server per test (not per module): the mutation run then maps every test to the code it starts."""
    src = WebSource(port=0, certificate=certificate, token="s3cr3t-Session-Token").start()
    yield src
    src.stop()


def _tls() -> ssl.SSLContext:
    ctx = ssl.create_default_context()
    ctx.check_hostname = False
    ctx.verify_mode = ssl.CERT_NONE
    return ctx


def _status(url: str) -> int:
    try:
        with urlopen(url, context=_tls(), timeout=10) as r:
            return r.status
    except HTTPError as err:
        err.close()
        return err.code


def _wrong_tokens(token: str) -> list[str]:
    return ["", token[:-1], token[:4], token + "x", token[1:], "S" + token[1:], token.upper()]


@pytest.mark.parametrize("page", ["/", "/index.html"])
def test_a_controller_page_needs_the_exact_token(source, page):
    base = f"https://127.0.0.1:{source.port}{page}"
    assert _status(f"{base}?t={source.token}") == 200
    assert _status(base) == 403
    for wrong in _wrong_tokens(source.token):
        assert _status(f"{base}?t={wrong}") == 403, wrong


def test_the_websocket_needs_the_exact_token(source):
    with connect(f"wss://127.0.0.1:{source.port}/ws?t={source.token}", ssl=_tls(), open_timeout=10) as ws:
        assert "hello" in ws.recv(timeout=10)
    for wrong in _wrong_tokens(source.token):
        with (
            pytest.raises(InvalidStatus),
            connect(f"wss://127.0.0.1:{source.port}/ws?t={wrong}", ssl=_tls(), open_timeout=10),
        ):
            pass


def test_static_files_carry_no_secret_and_need_no_token(source):
    """The script and style are the same for every session; only what opens a controller is guarded."""
    assert _status(f"https://127.0.0.1:{source.port}/app.js") == 200
    assert _status(f"https://127.0.0.1:{source.port}/style.css") == 200
    with urlopen(f"https://127.0.0.1:{source.port}/app.js", context=_tls(), timeout=10) as r:
        assert source.token not in r.read().decode()
