"""The web controller: any phone's browser as a MotionStick, no app to install.

``--source web`` serves a small page over HTTPS (a certificate made once and kept in
the user's data folder, :mod:`input.web.cert`) and takes its readings over a WebSocket
(:mod:`input.web.server`); :mod:`input.web.protocol` is the one place the page's
messages are checked and turned into pose samples. The page itself is plain
HTML/JS in ``page/``, shipped as package data.
"""

from input.web.cert import WebCertificate, load_or_create
from input.web.protocol import ControllerMessage, WebMessageError, parse_message
from input.web.server import DEFAULT_WEB_PORT, WebSource

__all__ = [
    "WebSource",
    "DEFAULT_WEB_PORT",
    "WebCertificate",
    "load_or_create",
    "ControllerMessage",
    "WebMessageError",
    "parse_message",
]
