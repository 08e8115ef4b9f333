"""The web controller's TLS certificate: made once, kept in the user's data folder, shown by fingerprint.

Browsers give a page the phone's motion sensors (and WebXR) only in a secure context,
so the controller page is served over HTTPS even on a LAN. No public authority can
sign for a LAN address, so the engine signs its own certificate the first time it is
needed (``cryptography``: an ECDSA P-256 key, valid 825 days, the longest iOS trusts)
and keeps it in ``$XDG_DATA_HOME/puppetphone/web/`` (``~/.local/share/...``), so a
phone that trusted it once keeps trusting it. Its SHA-256 fingerprint is printed so
the user can compare it with what the phone's browser shows before accepting it.

The files are written atomically (a crash never leaves half a key), the key readable
by the user only. Unreadable or expired files, or a key that does not belong to the
certificate (one of the two replaced), are replaced by a new pair, with a line saying so.
"""

from __future__ import annotations

import datetime as _dt
import ipaddress
import os
import ssl
import sys
from dataclasses import dataclass
from pathlib import Path

from engine.atomic import atomic_write_bytes

__all__ = ["WebCertificate", "load_or_create", "data_folder", "fingerprint", "VALID_DAYS"]

VALID_DAYS = 825


def data_folder() -> Path:
    """``$XDG_DATA_HOME/puppetphone/web`` (``~/.local/share/puppetphone/web`` without it)."""
    base = os.environ.get("XDG_DATA_HOME") or str(Path.home() / ".local" / "share")
    return Path(base) / "puppetphone" / "web"


@dataclass(frozen=True)
class WebCertificate:
    """Where the certificate and key are, and the certificate's SHA-256 fingerprint."""

    cert_path: Path
    key_path: Path
    fingerprint: str
    created: bool

    def ssl_context(self) -> ssl.SSLContext:
        """A server context for this certificate (TLS 1.2 and up) that sends no TLS 1.3 session tickets.

        By default a TLS 1.3 server sends two tickets just after the handshake, unasked. A client
        that reads on one thread while it writes its upgrade request on another (``websockets``'
        threaded client, which the tests and the benches use) then has CPython's ``ssl`` (before
        3.13.6) read the tickets and write the request on one OpenSSL connection at once, which
        OpenSSL does not allow; about one handshake in 500 lost its request under load and waited
        out its 10 s timeout (CI, ``test_a_web_phone_is_released_after_the_silence_it_was_given``).
        Without tickets the server says nothing until the request has come. A reconnecting phone
        pays a full handshake instead of a resumed one: a few milliseconds on a LAN.
        """
        ctx = ssl.SSLContext(ssl.PROTOCOL_TLS_SERVER)
        ctx.minimum_version = ssl.TLSVersion.TLSv1_2
        ctx.num_tickets = 0
        ctx.load_cert_chain(self.cert_path, self.key_path)
        return ctx


def fingerprint(der: bytes) -> str:
    """``AB:CD:...``: the SHA-256 of a DER certificate as browsers display it."""
    import hashlib

    digest = hashlib.sha256(der).hexdigest().upper()
    return ":".join(digest[i : i + 2] for i in range(0, len(digest), 2))


def _usable(cert_path: Path, key_path: Path) -> tuple[bytes | None, str]:
    """The DER of a readable, unexpired certificate whose key loads and belongs to it, else why not."""
    from cryptography import x509
    from cryptography.hazmat.primitives import serialization

    if not cert_path.exists() and not key_path.exists():
        return None, ""
    try:
        cert = x509.load_pem_x509_certificate(cert_path.read_bytes())
        key = serialization.load_pem_private_key(key_path.read_bytes(), password=None)
    except (OSError, ValueError, TypeError):
        return None, "unreadable"
    spki = serialization.Encoding.DER, serialization.PublicFormat.SubjectPublicKeyInfo
    if key.public_key().public_bytes(*spki) != cert.public_key().public_bytes(*spki):
        return None, "the key does not belong to the certificate (one of them was replaced)"
    if cert.not_valid_after_utc <= _dt.datetime.now(_dt.UTC) + _dt.timedelta(days=1):
        return None, "expired"
    return cert.public_bytes(serialization.Encoding.DER), ""


def _create(addresses: list[str]) -> tuple[bytes, bytes, bytes]:
    """A new self-signed certificate for ``localhost`` and ``addresses``: (cert PEM, key PEM, DER)."""
    from cryptography import x509
    from cryptography.hazmat.primitives import hashes, serialization
    from cryptography.hazmat.primitives.asymmetric import ec
    from cryptography.x509.oid import ExtendedKeyUsageOID, NameOID

    key = ec.generate_private_key(ec.SECP256R1())
    name = x509.Name(
        [
            x509.NameAttribute(NameOID.COMMON_NAME, "PuppetPhone controller"),
            x509.NameAttribute(NameOID.ORGANIZATION_NAME, "PuppetPhone"),
        ]
    )
    alt: list[x509.GeneralName] = [x509.DNSName("localhost"), x509.IPAddress(ipaddress.ip_address("127.0.0.1"))]
    for a in addresses:
        try:
            ip = ipaddress.ip_address(a)
        except ValueError:
            continue
        if x509.IPAddress(ip) not in alt:
            alt.append(x509.IPAddress(ip))
    now = _dt.datetime.now(_dt.UTC)
    cert = (
        x509.CertificateBuilder()
        .subject_name(name)
        .issuer_name(name)
        .public_key(key.public_key())
        .serial_number(x509.random_serial_number())
        .not_valid_before(now - _dt.timedelta(minutes=5))
        .not_valid_after(now + _dt.timedelta(days=VALID_DAYS))
        .add_extension(x509.SubjectAlternativeName(alt), critical=False)
        .add_extension(x509.BasicConstraints(ca=False, path_length=None), critical=True)
        .add_extension(x509.ExtendedKeyUsage([ExtendedKeyUsageOID.SERVER_AUTH]), critical=False)
        .sign(key, hashes.SHA256())
    )
    key_pem = key.private_bytes(
        serialization.Encoding.PEM, serialization.PrivateFormat.PKCS8, serialization.NoEncryption()
    )
    return cert.public_bytes(serialization.Encoding.PEM), key_pem, cert.public_bytes(serialization.Encoding.DER)


def load_or_create(addresses: list[str], folder: Path | None = None) -> WebCertificate:
    """The kept certificate, or a new one (covering ``localhost`` and ``addresses``) written there.

    Raises:
        OSError: the data folder cannot be written.
    """
    folder = data_folder() if folder is None else folder
    cert_path, key_path = folder / "cert.pem", folder / "key.pem"
    der, why = _usable(cert_path, key_path)
    if der is not None:
        return WebCertificate(cert_path, key_path, fingerprint(der), created=False)
    if why:
        print(
            f"web: the certificate in {folder} cannot be used ({why}): made a new one; phones must accept it again",
            file=sys.stderr,
        )
    folder.mkdir(parents=True, exist_ok=True)
    cert_pem, key_pem, der = _create(addresses)
    old = os.umask(0o077)  # the key is the user's alone
    try:
        atomic_write_bytes(key_path, key_pem)
    finally:
        os.umask(old)
    os.chmod(key_path, 0o600)
    atomic_write_bytes(cert_path, cert_pem)
    return WebCertificate(cert_path, key_path, fingerprint(der), created=True)
