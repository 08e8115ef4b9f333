"""``puppetphone devices``: what is connected, where a phone should send, and a QR code."""

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
    print(f"(by default play --source osc listens on {DEFAULT_HOST} only, this machine; a phone on the LAN "
          "needs --osc-host 0.0.0.0 as above)")
    if info.urls and not args.no_qr:
        print(f"\nScan to pair ({info.urls[0]}):")
        print(qr_ascii(info.urls[0]))
    return 0
