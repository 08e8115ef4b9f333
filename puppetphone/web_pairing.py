"""The game window's pairing panel for ``--source web``: link, QR code and fingerprint until a phone connects.

A new user starts ``play … --source web`` and looks at the game window, not at the
terminal: so the window shows what the terminal printed — the link with its session
token, its QR code (a picture the phone's camera can scan off the screen) and the
certificate's SHA-256 fingerprint to check against the browser's warning — for as long
as no page is connected, and hides it once one is (a phone that drops out brings it back).
"""

from __future__ import annotations

import sys
from functools import lru_cache
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from engine.render.scene import RenderScene
from input.hub import InputHub

if TYPE_CHECKING:  # the web server's modules load asyncio, websockets and OSC: only a web source needs them
    from input.web.server import WebSource

__all__ = ["web_pairing_lines", "draw_web_pairing", "qr_picture", "web_sources"]

#: Side of the QR code as a fraction of the window's height.
QR_HEIGHT = 0.42


def web_sources(hub: InputHub) -> list[WebSource]:
    """The hub's web sources, found without importing the web server (asyncio, websockets, TLS: a
    tenth of a second of every start) when there are none: a ``WebSource`` exists only once its
    module was imported."""
    server = sys.modules.get("input.web.server")
    return [] if server is None else [s for s in hub.sources if isinstance(s, server.WebSource)]


def _waiting(hub: InputHub) -> list[WebSource]:
    return [s for s in web_sources(hub) if not s.viewers]


def web_pairing_lines(hub: InputHub) -> list[str]:
    """The link, fingerprint and steps for each web source no phone is connected to yet."""
    waiting = _waiting(hub)
    if not waiting:
        return []
    from input.web.pairing import web_link

    lines = []
    for source in waiting:
        link = web_link(source)
        lines.append("Phone: scan the QR code (or open the link) with the phone's camera, same Wi-Fi")
        lines += link.lines()[1:]
        lines.append("  then tap Start, point the phone at this screen and tap 'I am pointing at the screen'")
    return lines


@lru_cache(maxsize=4)
def qr_picture(text: str, module_px: int = 6) -> NDArray[np.uint8]:
    """A QR code of ``text`` as an RGBA picture: black modules on white, ``module_px`` pixels each."""
    from input.pairing import qr_matrix

    dark = np.kron(qr_matrix(text), np.ones((module_px, module_px), dtype=bool))
    grey = np.where(dark, 0, 255).astype(np.uint8)
    return np.dstack([grey, grey, grey, np.full_like(grey, 255)])


def draw_web_pairing(scene: RenderScene, hub: InputHub, size: tuple[int, int]) -> None:
    """The QR code of the first waiting web source, square, at the right of the window."""
    waiting = _waiting(hub)
    if not waiting or size[0] <= 0 or size[1] <= 0:
        return
    from input.web.pairing import web_link

    picture = qr_picture(web_link(waiting[0]).urls[0])
    h = QR_HEIGHT
    w = h * size[1] / size[0]
    scene.add_overlay(picture, rect=(1.0 - w - 0.02, 0.5 - h / 2, 1.0 - 0.02, 0.5 + h / 2))
