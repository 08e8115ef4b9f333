"""Pairing information: where a phone should send, which devices are plugged in.

Shared by ``puppetphone devices`` and the in-game overlay (which adds a live
packets/s light per source from ``InputHub.statuses()``). LAN addresses are read
from the network interfaces (no packet is sent); the QR code encodes
``osc.udp://ADDRESS:PORT/`` for the phone to scan.
"""

from __future__ import annotations

import io
import socket
import struct
import sys
from dataclasses import dataclass, field
from typing import Any

from input.hid import enumerate_supported
from input.osc import DEFAULT_PORT

__all__ = ["PairingInfo", "pairing_info", "lan_addresses", "qr_ascii", "qr_matrix", "serial_ports"]


@dataclass
class PairingInfo:
    """What to show a user who wants to connect a controller."""

    port: int
    bind_host: str
    addresses: list[str]
    hid_devices: list[dict[str, Any]] = field(default_factory=list)
    serial_ports: list[dict[str, Any]] = field(default_factory=list)

    @property
    def urls(self) -> list[str]:
        """``osc.udp://addr:port/`` for every LAN address."""
        return [f"osc.udp://{a}:{self.port}/" for a in self.addresses]

    @property
    def note(self) -> str:
        """A warning when the bind address cannot be reached from a phone."""
        if self.bind_host in ("0.0.0.0", ""):
            return ""
        return (
            f"OSC listens on {self.bind_host} only: a phone on the LAN cannot reach it; start with --osc-host 0.0.0.0"
        )

    @property
    def play_command(self) -> str:
        """The ``play`` command line that listens where these addresses (and the QR code) point."""
        return f"puppetphone play snowman --source osc --osc-host {self.bind_host or '0.0.0.0'} --osc-port {self.port}"

    def lines(self) -> list[str]:
        """The human-readable listing (``puppetphone devices`` and the overlay)."""
        out = [f"Phone (OSC over UDP): send to port {self.port} at"]
        out += [f"  {a}   ({u})" for a, u in zip(self.addresses, self.urls, strict=True)] or [
            "  (no LAN address found)"
        ]
        out.append("  ZIG SIM: Settings > IP address / Port; Sensors2OSC: host and port in Settings")
        if self.note:
            out.append(f"  note: {self.note}")
        out.append("HID devices:")
        out += [
            f"  {d['name']} [{d['vendor_id']:04x}:{d['product_id']:04x}] ({d['kind']})" for d in self.hid_devices
        ] or ["  none recognised (SpaceMouse, DualShock 4, DualSense)"]
        out.append("Serial ports:")
        out += [f"  {p['device']}  {p['description']}" for p in self.serial_ports] or ["  none"]
        return out


def lan_addresses() -> list[str]:
    """IPv4 addresses of the machine's non-loopback interfaces."""
    found: list[str] = []
    if sys.platform.startswith("linux"):
        import fcntl

        s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        try:
            for _, name in socket.if_nameindex():
                try:
                    req = struct.pack("256s", name.encode()[:15])
                    addr = socket.inet_ntoa(fcntl.ioctl(s.fileno(), 0x8915, req)[20:24])  # SIOCGIFADDR
                except OSError:
                    continue  # interface without an IPv4 address
                if not addr.startswith("127.") and addr not in found:
                    found.append(addr)
        finally:
            s.close()
    if not found:
        try:
            for addr in socket.gethostbyname_ex(socket.gethostname())[2]:
                if not addr.startswith("127.") and addr not in found:
                    found.append(addr)
        except OSError:
            pass
    return found


def serial_ports() -> list[dict[str, Any]]:
    """Serial ports pyserial can see."""
    from serial.tools import list_ports

    return [
        {"device": p.device, "description": p.description, "vid": p.vid, "pid": p.pid}
        for p in sorted(list_ports.comports(), key=lambda p: p.device)
    ]


def qr_ascii(text: str) -> str:
    """A QR code of ``text`` drawn with block characters for a terminal."""
    import qrcode

    qr = qrcode.QRCode(border=1)
    qr.add_data(text)
    qr.make(fit=True)
    out = io.StringIO()
    qr.print_ascii(out=out, invert=True)
    return out.getvalue()


def qr_matrix(text: str) -> Any:
    """A QR code of ``text`` as a boolean ``[n, n]`` array (True: a dark module), with a quiet zone of 4."""
    import numpy as np
    import qrcode

    qr = qrcode.QRCode(border=4)
    qr.add_data(text)
    qr.make(fit=True)
    return np.array(qr.get_matrix(), dtype=bool)


def pairing_info(port: int = DEFAULT_PORT, bind_host: str = "0.0.0.0") -> PairingInfo:
    """Everything ``puppetphone devices`` and the pairing overlay show."""
    try:
        hid_devices = enumerate_supported()
    except OSError:
        hid_devices = []
    return PairingInfo(
        port=port, bind_host=bind_host, addresses=lan_addresses(), hid_devices=hid_devices, serial_ports=serial_ports()
    )
