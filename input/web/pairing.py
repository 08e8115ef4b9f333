"""Telling a user how to reach the web controller: its URL, QR code and certificate fingerprint.

``play --source web`` prints this when the server starts and publishes the running
session's link in the data folder (``session.json`` beside the certificate), so that
``puppetphone devices``, run in another terminal, can show the same QR code. The link
holds the session token; the file is the user's alone and is removed when the session
ends (a stale one, whose process is gone, is ignored).
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from engine.atomic import atomic_write_bytes
from input.web.cert import data_folder

if TYPE_CHECKING:
    from input.web.server import WebSource

__all__ = ["WebLink", "web_link", "publish", "unpublish", "running_session"]

_LOOPBACK = ("127.", "localhost", "::1")


@dataclass(frozen=True)
class WebLink:
    """Where a phone opens the controller, and what it should trust."""

    urls: list[str]
    fingerprint: str
    loopback_only: bool

    def lines(self) -> list[str]:
        """The human-readable listing (``play --source web`` and ``devices``)."""
        out = ["Phone (web browser): open"]
        out += [f"  {u}" for u in self.urls]
        out.append(f"  certificate SHA-256: {self.fingerprint}")
        out.append("  the browser warns once about the self-signed certificate: check the fingerprint, then accept")
        if self.loopback_only:
            out.append("  note: this machine only; a phone on the LAN needs --web-host 0.0.0.0")
        return out


def web_link(source: WebSource) -> WebLink:
    """The link of a running :class:`input.web.server.WebSource`."""
    from input.pairing import lan_addresses

    host = source.host
    addresses = lan_addresses() or ["127.0.0.1"] if host in ("0.0.0.0", "") else [host]
    urls = [source.url(a) for a in addresses]
    loopback = all(a.startswith(_LOOPBACK) for a in addresses)
    return WebLink(urls, source.certificate.fingerprint, loopback)


def _session_file(folder: Path | None) -> Path:
    return (data_folder() if folder is None else folder) / "session.json"


def publish(link: WebLink, folder: Path | None = None) -> Path:
    """Write the running session's link for ``devices`` (readable by the user only)."""
    path = _session_file(folder)
    data = json.dumps(
        {"pid": os.getpid(), "urls": link.urls, "fingerprint": link.fingerprint, "loopback_only": link.loopback_only}
    ).encode()
    old = os.umask(0o077)
    try:
        atomic_write_bytes(path, data)
    finally:
        os.umask(old)
    return path


def unpublish(folder: Path | None = None) -> None:
    """Remove this process's published link (another process's is left alone)."""
    path = _session_file(folder)
    try:
        if json.loads(path.read_text()).get("pid") == os.getpid():
            path.unlink()
    except (OSError, ValueError, AttributeError):
        pass


def running_session(folder: Path | None = None) -> WebLink | None:
    """The link a running ``play --source web`` published, or ``None``."""
    try:
        data = json.loads(_session_file(folder).read_text())
        pid = int(data["pid"])
        os.kill(pid, 0)
        return WebLink([str(u) for u in data["urls"]], str(data["fingerprint"]), bool(data["loopback_only"]))
    except (OSError, ValueError, KeyError, TypeError):
        return None
