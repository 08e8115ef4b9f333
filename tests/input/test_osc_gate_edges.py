"""The OSC source's settings and the gate's exact edges: defaults, the queue, a datagram of exactly
the size limit, budgets spent to the last message, and what each drop's detail names.

Datagram by datagram on a fake clock, as ``test_osc_gate.py``; written against the mutation run's
survivors (docs/mutation.md), each test names the mutants that broke it.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from engine import quat
from input.osc import ADMIT_AFTER, MAX_BUNDLE_DEPTH, MAX_DATAGRAM, MAX_MESSAGES, OscSource, bundle_shape
from input.phone_frames import phone_to_stick
from input.sample import CONNECT, DISCONNECT, PoseSample

Message = Callable[..., bytes]
PHONE, OTHER = "osc:10.0.0.1", "osc:10.0.0.2"
_BUNDLE_HEAD = b"#bundle\x00" + b"\x00" * 8


def flat(elements: list[bytes]) -> bytes:
    return _BUNDLE_HEAD + b"".join(len(e).to_bytes(4, "big") + e for e in elements)


def nested(depth: int, inner: bytes) -> bytes:
    for _ in range(depth):
        inner = flat([inner])
    return inner


def samples(items: list[PoseSample | tuple[str, str]]) -> list[PoseSample]:
    return [i for i in items if isinstance(i, PoseSample)]


def admitted(src: OscSource, pose: bytes, sender: str = PHONE) -> OscSource:
    items: list[PoseSample | tuple[str, str]] = []
    for k in range(src.admit_after):  # one datagram a step
        src.handle_datagram(pose, sender, k * 1e-3, 5000)
        items += src.drain()
    assert (CONNECT, sender) in items
    return src


def test_the_defaults_are_the_documented_ones(source: Callable[..., OscSource], pose: bytes) -> None:
    """Loopback, one phone, 400 datagrams/s with a one-second burst, 2 s of silence, a queue of 256.
    Broken by: another default host, ``max_senders``, ``max_rate``, ``timeout`` or ``capacity``."""
    src = source()
    assert src.host == "127.0.0.1"  # the pairing overlay shows it
    assert src.name == f"osc 127.0.0.1:{src.port}" and src.status().connected is False
    assert src.admit_after == ADMIT_AFTER
    admitted(src, pose)
    src.handle_datagram(pose, OTHER, 0.01, 5000)
    assert src.status().locked_out == [OTHER]  # one slot
    passed = 0
    for _ in range(401):  # a full bucket passes 400 at once (minus the admission's three, refilled by now)
        src.handle_datagram(pose, PHONE, 10.0, 5000)
        passed += len(samples(src.drain()))
    assert passed == 400 and src.status().drop_reasons["rate limit"] == 1
    src._expire(12.0)
    assert src.drain() == []  # exactly 2 s: still there
    src._expire(12.01)
    assert src.drain() == [(DISCONNECT, PHONE)]
    sample = PoseSample(time=0.0, source=PHONE, orientation=np.array([1.0, 0.0, 0.0, 0.0]))
    for _ in range(257):
        src.push(sample)
    assert src.status().drop_reasons["queue full"] == 1 and len(src.drain()) == 256


def test_the_queue_holds_capacity_items(source: Callable[..., OscSource]) -> None:
    """Broken by: ``capacity`` not handed to the queue (unbounded, or the default 256)."""
    src = source(capacity=4)
    sample = PoseSample(time=0.0, source=PHONE, orientation=np.array([1.0, 0.0, 0.0, 0.0]))
    for _ in range(5):
        src.push(sample)
    assert src.status().drop_reasons == {"queue full": 1} and len(src.drain()) == 4


def test_the_gyrosc_order_reaches_the_decoder(source: Callable[..., OscSource], osc: tuple[Message, Message]) -> None:
    """Broken by: the source building its decoder with the default order."""
    message, _ = osc
    q = quat.from_axis_angle([1.0, 0.0, 0.0], 0.7)
    xyzw = [float(v) for v in quat.to_xyzw(q)]
    src = source(gyrosc_order="xyzw", admit_after=1)
    src.handle_datagram(message("/gyrosc/quat", *xyzw), PHONE, 0.0, 5000)
    got = samples(src.drain())
    assert len(got) == 1 and np.allclose(got[0].orientation, phone_to_stick(q))


def test_the_highest_port_is_a_valid_setting() -> None:
    """65535 passes the range check (it may be taken on this machine: then binding it fails, an
    ``OSError``, never the ``ValueError`` of a bad setting). Broken by: ``< 65535``."""
    try:
        OscSource(port=65535).stop()
    except OSError as exc:
        assert not isinstance(exc, ValueError)
        assert str(exc).startswith("cannot listen for OSC on 127.0.0.1:65535: ")


def test_a_datagram_of_exactly_the_size_limit_is_decoded(source: Callable[..., OscSource], pose: bytes) -> None:
    """:data:`MAX_DATAGRAM` bytes is also an admitted sender's whole byte budget for a step. Broken by:
    ``>=`` for the size limit, ``<=`` for the byte budget."""
    src = admitted(source(), pose)
    full = flat([pose]) + b"\x00" * (MAX_DATAGRAM - len(flat([pose])))
    assert len(full) == MAX_DATAGRAM
    src.handle_datagram(full, PHONE, 0.01, 5000)
    assert len(samples(src.drain())) == 1 and set(src.status().drop_reasons) == {"sender pending"}


def test_a_bundle_of_exactly_the_message_budget_is_decoded(
    source: Callable[..., OscSource], osc: tuple[Message, Message]
) -> None:
    """Broken by: ``<=`` for the message budget (a whole ZIG SIM bundle refused)."""
    message, _ = osc
    src = admitted(source(), message("/puppetphone/orientation", 1.0, 0.0, 0.0, 0.0))
    touch = message("/puppetphone/touch", 1)
    src.handle_datagram(flat([touch] * MAX_MESSAGES), PHONE, 0.01, 5000)
    got = samples(src.drain())
    assert len(got) == 1 and got[0].touch is True and set(src.status().drop_reasons) == {"sender pending"}


def test_a_refused_bundle_is_not_decoded(source: Callable[..., OscSource], pose: bytes) -> None:
    """A bundle too deep holding a valid pose yields nothing. Broken by: refusing it but decoding it anyway."""
    src = admitted(source(), pose)
    src.handle_datagram(nested(MAX_BUNDLE_DEPTH + 1, pose), PHONE, 0.01, 5000)
    assert src.drain() == []
    assert src.status().last_error == f"bundle too deep: {PHONE}"


def test_every_drop_names_its_sender(source: Callable[..., OscSource], pose: bytes) -> None:
    """The overlay shows the last drop: which address was pending, refused, limited. Broken by: a
    detail of ``None`` or none at all."""
    src = source(max_senders=2, admit_after=2, max_rate=3.0)
    src.handle_datagram(pose, PHONE, 0.0, 5000)
    assert src.status().last_error == f"sender pending: {PHONE}"
    for _ in range(3):
        src.handle_datagram(b"garbage", OTHER, 0.0, 5000)
    assert src.status().last_error == f"over budget: {OTHER}"  # a candidate's two datagrams a step
    for _ in range(3):  # admitted by the first, then the bucket's third token, then none left
        src.handle_datagram(pose, PHONE, 0.0, 5000)
    assert src.status().last_error == f"rate limit: {PHONE}"
    src.handle_datagram(flat([pose] * (MAX_MESSAGES + 1)), OTHER, 1.0, 5000)
    assert src.status().last_error == f"bundle too large: {OTHER}"


def test_a_pose_from_another_port_does_not_refill_the_phones_own_bucket(
    source: Callable[..., OscSource], pose: bytes
) -> None:
    """The own port's bucket refills from its own last datagram, not from when the phone was last
    seen on another port. Broken by: refilling from the last-seen time."""
    src = admitted(source(admit_after=1, max_rate=2.0), pose)
    src.handle_datagram(pose, PHONE, 0.0, 5000)  # the own bucket is empty now
    src.handle_datagram(pose, PHONE, 1.0, 6000)  # seen at 1.0 s, on another port
    src.drain()
    src.handle_datagram(pose, PHONE, 1.0, 5000)  # a second's refill since its own last datagram: two tokens
    src.handle_datagram(pose, PHONE, 1.0, 5000)
    assert len(samples(src.drain())) == 2 and "rate limit" not in src.status().drop_reasons


def test_elements_are_counted_by_their_size_field_alone() -> None:
    """A one-byte element is not a message python-osc will take, but it is walked and counted like
    any other, so a bundle of many of them is refused as too large before it is parsed. Broken by:
    a size of 1 ending the walk (``n <= 1``)."""
    assert bundle_shape(flat([b"\x00"])) == (1, "")
    assert bundle_shape(flat([b"\x00"] * (MAX_MESSAGES + 1)))[1] == "bundle too large"
