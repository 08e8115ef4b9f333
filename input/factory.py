"""Building an :class:`InputHub` from the command line's ``--source`` choice.

``--source mouse|osc|hid|serial[:PORT]|web|replay:FILE`` plus ``--osc-host``,
``--osc-port``, ``--serial-port``, ``--baud``, ``--web-host`` and ``--web-port``. :func:`add_source_arguments`
adds these options to a parser (``play`` uses it) and :func:`make_hub` builds the
hub they describe; it does not start the sources.
"""

from __future__ import annotations

import argparse

from input.hub import InputHub
from input.osc import DEFAULT_PORT
from input.web.server import DEFAULT_WEB_PORT

__all__ = ["add_source_arguments", "make_hub", "SOURCE_KINDS", "DEFAULT_HOST"]

SOURCE_KINDS = ("mouse", "osc", "hid", "serial", "web", "replay:FILE")
#: Where OSC listens unless told otherwise: this machine only (a LAN phone needs 0.0.0.0).
DEFAULT_HOST = "127.0.0.1"


def add_source_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``--source`` and the device options to a sub-command's parser."""
    parser.add_argument("--source", default="mouse", help=f"input source: {'|'.join(SOURCE_KINDS)} (default mouse)")
    parser.add_argument("--osc-host", default=DEFAULT_HOST,
                        help="OSC bind address; phones on the LAN need 0.0.0.0 (default 127.0.0.1)")
    parser.add_argument("--osc-port", type=int, default=DEFAULT_PORT, help=f"OSC UDP port (default {DEFAULT_PORT})")
    parser.add_argument("--osc-senders", type=int, default=1, help="how many phones may drive sticks (default 1)")
    parser.add_argument("--serial-port", default=None, help="serial device or pyserial URL (or --source serial:PORT)")
    parser.add_argument("--baud", type=int, default=115200, help="serial baud rate (default 115200)")
    parser.add_argument("--web-host", default=DEFAULT_HOST,
                        help="web controller bind address; phones on the LAN need 0.0.0.0 (default 127.0.0.1)")
    parser.add_argument("--web-port", type=int, default=DEFAULT_WEB_PORT,
                        help=f"web controller HTTPS port, 0 for any free one (default {DEFAULT_WEB_PORT})")


def make_hub(source: str = "mouse", osc_host: str = DEFAULT_HOST, osc_port: int = DEFAULT_PORT,
             osc_senders: int = 1, serial_port: str | None = None, baud: int = 115200,
             web_host: str = DEFAULT_HOST, web_port: int = DEFAULT_WEB_PORT) -> InputHub:
    """The hub for one ``--source`` value (sources not yet started).

    Raises:
        ValueError: unknown source, or a serial source without a port.
        OSError: the OSC or web port cannot be bound (or the web certificate cannot be kept).
        input.recording.RecordingError: an unreadable replay file.
    """
    kind, _, arg = source.partition(":")
    if kind == "mouse":
        from input.mouse import MouseSource

        return InputHub([MouseSource()])
    if kind == "osc":
        from input.osc import OscSource

        return InputHub([OscSource(host=osc_host, port=int(arg) if arg else osc_port, max_senders=osc_senders)])
    if kind == "hid":
        from input.hid import HidSource

        return InputHub([HidSource()])
    if kind == "serial":
        from input.serial_source import SerialSource

        port = arg or serial_port
        if not port:
            raise ValueError("--source serial needs a port: --source serial:/dev/ttyUSB0 or --serial-port")
        return InputHub([SerialSource(port, baudrate=baud)])
    if kind == "web":
        from input.web.server import WebSource

        return InputHub([WebSource(host=web_host, port=int(arg) if arg else web_port)])
    if kind == "replay":
        from input.replay import replay_hub

        if not arg:
            raise ValueError("--source replay needs a file: --source replay:session.rec")
        return replay_hub(arg)
    raise ValueError(f"unknown input source {source!r}; choose {', '.join(SOURCE_KINDS)}")
