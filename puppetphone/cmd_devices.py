"""``puppetphone devices``: what is connected, where a phone should send, and a QR code.

The web controller's link carries a session token made by each ``play --source web``,
so its QR code is shown while such a session runs (it publishes its link); otherwise
the command to start one.
"""

from __future__ import annotations

import argparse

__all__ = ["configure", "run"]


def configure(parser: argparse.ArgumentParser) -> None:
    """Add the devices arguments."""
    parser.add_argument("--osc-port", type=int, default=None, help="the port play will listen on (default 9000)")
    parser.add_argument("--osc-host", default="0.0.0.0", help="the bind address play will use (default 0.0.0.0)")
    parser.add_argument("--no-qr", action="store_true", help="do not draw the QR code")


def run(args: argparse.Namespace) -> int:
    """Print recognised HID devices, serial ports, OSC addresses and a QR code."""
    from input.factory import DEFAULT_HOST
    from input.osc import DEFAULT_PORT
    from input.pairing import pairing_info, qr_ascii

    info = pairing_info(port=args.osc_port or DEFAULT_PORT, bind_host=args.osc_host)
    print("\n".join(info.lines()))
    print(f"\nTo play with the phone, start:\n  {info.play_command}")
    print(
        f"(by default play --source osc listens on {DEFAULT_HOST} only, this machine; a phone on the LAN "
        "needs --osc-host 0.0.0.0 as above)"
    )
    if info.urls and not args.no_qr:
        print(f"\nScan to pair ({info.urls[0]}):")
        print(qr_ascii(info.urls[0]))
    _web(args.no_qr)
    return 0


def _web(no_qr: bool) -> None:
    """The running web controller session's link and QR code, or how to start one."""
    from input.pairing import qr_ascii
    from input.web.pairing import running_session

    link = running_session()
    if link is None:
        print(
            "\nPhone (web browser, no app): no session is running; start one with\n"
            "  puppetphone play snowman --source web --web-host 0.0.0.0\n"
            "(it prints the link, its QR code and the certificate fingerprint; run devices again to see them here)"
        )
        return
    print("\n" + "\n".join(link.lines()))
    if not no_qr:
        print(f"\nScan with the phone's camera ({link.urls[0]}):")
        print(qr_ascii(link.urls[0]))
