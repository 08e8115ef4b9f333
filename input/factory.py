"""Building an :class:`InputHub` from the command line's ``--source`` choice.

``--source mouse|osc|hid|serial[:PORT]|web|replay:FILE`` plus ``--osc-host``,
``--osc-port``, ``--serial-port``, ``--baud``, ``--web-host``, ``--web-port`` and
``--silent-after``. :func:`add_source_arguments` adds these options to a parser (``play``
and ``author record`` use it) and :func:`make_hub` builds the hub they describe; it does
not start the sources.

``--silent-after SECONDS`` is how long an OSC or web controller may stay silent before its
puppet is released to the next phone (2 s by default: the web page sends at least four
readings a second and a phone app tens). It is refused (exit 2) outside
:data:`SILENT_AFTER_RANGE`: below a quarter second a phone on a busy Wi-Fi would lose its
puppet between two readings; past a minute a frozen phone would hold it as long as the old
WebSocket keep-alive did.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from input.hub import InputHub
    from input.source import PoseSource

__all__ = [
    "DEFAULT_HOST",
    "DEFAULT_SILENT_AFTER",
    "SILENT_AFTER_RANGE",
    "SOURCES",
    "SOURCE_KINDS",
    "SourceOptions",
    "add_source_arguments",
    "make_hub",
    "open_hub",
    "silent_after",
]

#: The OSC and web defaults, repeated here so parsing ``--help`` imports neither server (a test checks they agree).
DEFAULT_PORT = 9000
DEFAULT_WEB_PORT = 8443
#: Where OSC listens unless told otherwise: this machine only (a LAN phone needs 0.0.0.0).
DEFAULT_HOST = "127.0.0.1"
#: Seconds of silence after which an OSC or web controller's puppet goes to the next phone.
DEFAULT_SILENT_AFTER = 2.0
SILENT_AFTER_RANGE = (0.25, 60.0)


def silent_after(text: str) -> float:
    """``--silent-after``: seconds in :data:`SILENT_AFTER_RANGE` (argparse turns a refusal into exit 2)."""
    lo, hi = SILENT_AFTER_RANGE
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number of seconds") from None
    if not math.isfinite(value) or not lo <= value <= hi:
        raise argparse.ArgumentTypeError(f"{text} s is out of range: must be from {lo} to {hi} seconds")
    return value


def add_source_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``--source`` and the device options to a sub-command's parser."""
    parser.add_argument("--source", default="mouse", help=f"input source: {'|'.join(SOURCE_KINDS)} (default mouse)")
    parser.add_argument(
        "--osc-host", default=DEFAULT_HOST, help="OSC bind address; phones on the LAN need 0.0.0.0 (default 127.0.0.1)"
    )
    parser.add_argument("--osc-port", type=int, default=DEFAULT_PORT, help=f"OSC UDP port (default {DEFAULT_PORT})")
    parser.add_argument("--osc-senders", type=int, default=1, help="how many phones may drive sticks (default 1)")
    parser.add_argument("--serial-port", default=None, help="serial device or pyserial URL (or --source serial:PORT)")
    parser.add_argument("--baud", type=int, default=115200, help="serial baud rate (default 115200)")
    parser.add_argument(
        "--web-host",
        default=DEFAULT_HOST,
        help="web controller bind address; phones on the LAN need 0.0.0.0 (default 127.0.0.1)",
    )
    parser.add_argument(
        "--web-port",
        type=int,
        default=DEFAULT_WEB_PORT,
        help=f"web controller HTTPS port, 0 for any free one (default {DEFAULT_WEB_PORT})",
    )
    lo, hi = SILENT_AFTER_RANGE
    parser.add_argument(
        "--silent-after",
        type=silent_after,
        default=DEFAULT_SILENT_AFTER,
        metavar="SECONDS",
        help="an OSC or web controller silent this long loses its puppet to the next phone "
        f"({lo}..{hi:g}, default {DEFAULT_SILENT_AFTER:g})",
    )


@dataclass(frozen=True)
class SourceOptions:
    """The device options of the command line, as every source kind's builder reads them."""

    arg: str = ""
    osc_host: str = DEFAULT_HOST
    osc_port: int = DEFAULT_PORT
    osc_senders: int = 1
    serial_port: str | None = None
    baud: int = 115200
    web_host: str = DEFAULT_HOST
    web_port: int = DEFAULT_WEB_PORT
    silent_after: float = DEFAULT_SILENT_AFTER


def _mouse(o: SourceOptions) -> PoseSource:
    from input.mouse import MouseSource

    return MouseSource()


def _osc(o: SourceOptions) -> PoseSource:
    from input.osc import OscSource

    return OscSource(
        host=o.osc_host, port=int(o.arg) if o.arg else o.osc_port, max_senders=o.osc_senders, timeout=o.silent_after
    )


def _hid(o: SourceOptions) -> PoseSource:
    from input.hid import HidSource

    return HidSource()


def _serial(o: SourceOptions) -> PoseSource:
    from input.serial_source import SerialSource

    port = o.arg or o.serial_port
    if not port:
        raise ValueError("--source serial needs a port: --source serial:/dev/ttyUSB0 or --serial-port")
    return SerialSource(port, baudrate=o.baud)


def _web(o: SourceOptions) -> PoseSource:
    from input.web.server import WebSource

    return WebSource(host=o.web_host, port=int(o.arg) if o.arg else o.web_port, silent_after=o.silent_after)


#: Every live source kind by its ``--source`` name: adding a device is a builder and one line here.
SOURCES: dict[str, Callable[[SourceOptions], PoseSource]] = {
    "mouse": _mouse,
    "osc": _osc,
    "hid": _hid,
    "serial": _serial,
    "web": _web,
}
SOURCE_KINDS = (*SOURCES, "replay:FILE")


def open_hub(args: argparse.Namespace) -> InputHub:
    """The hub of a parsed command line's ``--source`` and device options (not started): every option passed."""
    return make_hub(
        args.source,
        args.osc_host,
        args.osc_port,
        args.osc_senders,
        args.serial_port,
        args.baud,
        args.web_host,
        args.web_port,
        args.silent_after,
    )


def make_hub(
    source: str = "mouse",
    osc_host: str = DEFAULT_HOST,
    osc_port: int = DEFAULT_PORT,
    osc_senders: int = 1,
    serial_port: str | None = None,
    baud: int = 115200,
    web_host: str = DEFAULT_HOST,
    web_port: int = DEFAULT_WEB_PORT,
    silent_after: float = DEFAULT_SILENT_AFTER,
) -> InputHub:
    """The hub for one ``--source`` value (sources not yet started).

    Raises:
        ValueError: unknown source, or a serial source without a port.
        OSError: the OSC or web port cannot be bound (or the web certificate cannot be kept).
        input.recording.RecordingError: an unreadable replay file.
    """
    from input.hub import InputHub

    kind, _, arg = source.partition(":")
    if kind == "replay":
        from input.replay import replay_hub

        if not arg:
            raise ValueError("--source replay needs a file: --source replay:session.rec")
        return replay_hub(arg)
    if kind not in SOURCES:
        raise ValueError(f"unknown input source {source!r}; choose {', '.join(SOURCE_KINDS)}")
    options = SourceOptions(arg, osc_host, osc_port, osc_senders, serial_port, baud, web_host, web_port, silent_after)
    return InputHub([SOURCES[kind](options)])
