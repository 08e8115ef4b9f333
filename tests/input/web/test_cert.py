"""After the TLS handshake the web server is silent until the client has spoken.

A TLS 1.3 server sends session tickets just after the handshake by default. ``websockets``'
threaded client (the tests' and the benches' phone) reads them on its reader thread while its
caller writes the upgrade request; CPython's ``ssl`` before 3.13.6 lets the two run on one OpenSSL
connection at once, and about one handshake in 500 lost its request under load: the first
handshake of ``tests/input/test_factory.py``'s silent-phone test waited out its 10 s in CI. The
server's context sends no tickets, so nothing arrives for the reader before the request is answered.

Broken once: ``ctx.num_tickets = 0`` removed from ``WebCertificate.ssl_context`` makes the first
test fail (the tickets are readable straight after the handshake).
"""

from __future__ import annotations

import base64
import os
import select
import socket
import ssl
from pathlib import Path

from input.web.cert import load_or_create
from input.web.server import WebSource


def _client() -> ssl.SSLContext:
    ctx = ssl.create_default_context()
    ctx.check_hostname, ctx.verify_mode = False, ssl.CERT_NONE
    ctx.minimum_version = ssl.TLSVersion.TLSv1_3  # where tickets come after the handshake, unasked
    return ctx


def test_nothing_arrives_after_the_handshake_until_the_upgrade_request_is_answered(tmp_path: Path) -> None:
    src = WebSource(port=0, certificate=load_or_create([], tmp_path / "web")).start()
    try:
        with socket.create_connection(("127.0.0.1", src.port), timeout=10) as raw:
            tls = _client().wrap_socket(raw, server_hostname="127.0.0.1")
            assert tls.version() == "TLSv1.3"
            readable, _, _ = select.select([tls], [], [], 1.0)  # tickets come within milliseconds when sent
            assert not readable and tls.pending() == 0, "the server sent records the client never asked for"
            key = base64.b64encode(os.urandom(16)).decode()
            tls.sendall(
                f"GET /ws?t={src.token} HTTP/1.1\r\nHost: 127.0.0.1:{src.port}\r\nUpgrade: websocket\r\n"
                f"Connection: Upgrade\r\nSec-WebSocket-Key: {key}\r\nSec-WebSocket-Version: 13\r\n\r\n".encode()
            )
            reply = b""
            while b"\r\n\r\n" not in reply:
                chunk = tls.recv(4096)
                assert chunk, f"closed before the upgrade was answered: {reply!r}"
                reply += chunk
            assert reply.startswith(b"HTTP/1.1 101"), reply[:80]  # silent by design, not dead
            tls.close()
    finally:
        src.stop()
