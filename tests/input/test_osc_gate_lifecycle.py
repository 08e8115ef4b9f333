"""The OSC gate over a sender's life: other ports of an admitted phone, two phones, candidates and
phones that go quiet and come back. Datagram by datagram on a fake clock, as ``test_osc_gate.py``.

Written against the mutation run's survivors (docs/mutation.md); each test names what broke it.
"""

from __future__ import annotations

from collections.abc import Callable

from input.osc import MAX_CANDIDATES, STEP_BUDGET, OscSource
from input.sample import CONNECT, DISCONNECT, PoseSample

Message = Callable[..., bytes]
PHONE, OTHER = "osc:10.0.0.1", "osc:10.0.0.2"


def times(items: list[PoseSample | tuple[str, str]]) -> list[float | tuple[str, str]]:
    """Events as they are, samples by their time: the whole drained sequence, comparable at a glance."""
    return [i if isinstance(i, tuple) else i.time for i in items]


def test_another_ports_bucket_refills_at_max_rate_and_stays_empty_while_flooded(
    source: Callable[..., OscSource], pose: bytes
) -> None:
    """Broken by: the other ports' bucket never refilled (``-`` for ``+``), refilled at ``1/max_rate``,
    its level lost (``None``) or written into its refill time when a datagram is refused."""
    src = source(admit_after=1, max_rate=4.0)
    src.handle_datagram(pose, PHONE, 0.0, 5000)
    src.drain()
    for _ in range(4):  # a full bucket: four at once
        src.handle_datagram(pose, PHONE, 10.0, 6000)
    src.handle_datagram(pose, PHONE, 10.0, 6000)
    src.handle_datagram(pose, PHONE, 10.1, 6000)  # 0.4 of a token: still refused
    assert src.status().drop_reasons == {"rate limit": 2}
    assert times(src.drain()) == [10.0] * 4
    src.handle_datagram(pose, PHONE, 10.5, 6000)  # 0.4 + 1.6 tokens: one goes through, 1.0 left
    src.handle_datagram(pose, PHONE, 10.5, 6000)
    src.handle_datagram(pose, PHONE, 10.5, 6000)
    assert times(src.drain()) == [10.5, 10.5]
    assert src.status().drop_reasons == {"rate limit": 3}


def test_each_phones_other_ports_have_a_bucket_and_budget_of_their_own(
    source: Callable[..., OscSource], pose: bytes
) -> None:
    """Two admitted phones: a flood from other ports of one does not spend the other's other-port
    allowance. Broken by: one key (``None``) for every phone's other ports, in the bucket or the budget."""
    src = source(max_senders=2, admit_after=1, max_rate=4.0)
    src.handle_datagram(pose, PHONE, 0.0, 5000)
    src.handle_datagram(pose, OTHER, 0.0, 5000)
    src.drain()
    for k in range(8):  # PHONE's other ports: four pass the bucket, four are refused
        src.handle_datagram(pose, PHONE, 1.0, 6000 + k)
    for k in range(4):  # OTHER's other ports have their own full bucket
        src.handle_datagram(pose, OTHER, 1.0, 7000 + k)
    assert src.status().drop_reasons == {"rate limit": 4}
    assert [s.source for s in src.drain()] == [PHONE] * 4 + [OTHER] * 4
    big = source(max_senders=2, admit_after=1)
    big.handle_datagram(pose, PHONE, 0.0, 5000)
    big.handle_datagram(pose, OTHER, 0.0, 5000)
    big.drain()
    for k in range(STEP_BUDGET[0] + 1):  # one step: PHONE's other ports spend their budget, and one more
        big.handle_datagram(pose, PHONE, 0.01, 6000 + k)
    for k in range(STEP_BUDGET[0]):
        big.handle_datagram(pose, OTHER, 0.01, 7000 + k)
    assert big.status().drop_reasons == {"over budget": 1}
    assert big.status().last_error == f"over budget: {PHONE}:other"
    assert len(big.drain()) == 2 * STEP_BUDGET[0]


def test_a_valid_pose_from_another_port_is_only_a_sample(source: Callable[..., OscSource], pose: bytes) -> None:
    """No second CONNECT, and the sample is the phone's. Broken by: delivered under no sender (``None``),
    which announced the source itself as connected again."""
    src = source(admit_after=1)
    src.handle_datagram(pose, PHONE, 0.0, 5000)
    src.drain()
    src.handle_datagram(pose, PHONE, 0.5, 6000)
    items = src.drain()
    assert times(items) == [0.5] and items[0].source == PHONE  # type: ignore[union-attr]


def test_a_lock_out_names_every_phone_that_holds_a_slot(source: Callable[..., OscSource], pose: bytes) -> None:
    """Broken by: the names joined by another separator."""
    src = source(max_senders=2, admit_after=1)
    src.handle_datagram(pose, PHONE, 0.0, 5000)
    src.handle_datagram(pose, OTHER, 0.0, 5000)
    src.handle_datagram(pose, "osc:10.0.0.3", 0.0, 5000)
    assert src.status().last_error == f"other sender: osc:10.0.0.3 (locked to {PHONE}, {OTHER})"


def test_a_candidate_quiet_for_exactly_the_timeout_is_still_a_candidate(
    source: Callable[..., OscSource], pose: bytes
) -> None:
    """Broken by: ``>=`` for ``>`` in the candidates' expiry (the admitted ones' is in test_osc_gate.py)."""
    src = source(admit_after=2, timeout=1.0)
    src.handle_datagram(pose, PHONE, 0.0, 5000)
    src._expire(1.0)
    src.drain()
    src.handle_datagram(pose, PHONE, 1.0, 5000)  # its second valid sample: admitted
    assert times(src.drain()) == [(CONNECT, PHONE), 1.0]


def test_a_candidate_that_sent_only_garbage_expires_cleanly(source: Callable[..., OscSource], pose: bytes) -> None:
    """The decoder has no state for it. Broken by: forgetting a sender the decoder does not know raising
    ``KeyError`` (``pop`` without its default), which ended the socket thread."""
    src = source(admit_after=1, timeout=1.0)
    src.handle_datagram(b"garbage", OTHER, 0.0, 5000)
    src._expire(2.0)
    src.handle_datagram(pose, PHONE, 2.0, 5000)
    assert times(src.drain()) == [(CONNECT, PHONE), 2.0]


def test_expired_candidates_free_their_places(source: Callable[..., OscSource], pose: bytes) -> None:
    """:data:`MAX_CANDIDATES` quiet candidates expire; as many new ones are then taken. Broken by: the
    expired left among the candidates (``pop(None)``), which then failed the next expiry."""
    src = source(admit_after=5, timeout=1.0)
    for k in range(MAX_CANDIDATES):
        src.handle_datagram(pose, f"osc:10.0.2.{k}", 0.0, 5000)
    src._expire(1.5)
    for k in range(MAX_CANDIDATES):
        src.handle_datagram(pose, f"osc:10.0.3.{k}", 1.5, 5000)
    src._expire(2.0)
    assert "too many senders" not in src.status().drop_reasons
    assert src.status().drop_reasons == {"sender pending": 2 * MAX_CANDIDATES}


def test_a_phone_back_after_a_timeout_starts_afresh(
    source: Callable[..., OscSource], osc: tuple[Message, Message]
) -> None:
    """It is admitted again like any new phone, announced again, with a fresh pose (a finger down
    before it went quiet is not still down) and full buckets for its other ports. Broken by: its
    decoder state, its other ports' bucket or its ``_active`` mark kept across the timeout."""
    message, _ = osc
    pose = message("/puppetphone/orientation", 1.0, 0.0, 0.0, 0.0)
    src = source(admit_after=1, timeout=0.5, max_rate=4.0)
    src.handle_datagram(message("/puppetphone/touch", 1), PHONE, 0.0, 5000)
    for _ in range(4):  # its other ports empty their bucket
        src.handle_datagram(pose, PHONE, 0.1, 6000)
    first = src.drain()
    assert first[0] == (CONNECT, PHONE) and first[1].touch is True  # type: ignore[union-attr]
    src._expire(0.7)
    assert src.drain() == [(DISCONNECT, PHONE)]
    src.handle_datagram(pose, PHONE, 0.7, 5000)
    again = src.drain()
    assert again[0] == (CONNECT, PHONE) and again[1].touch is None  # type: ignore[union-attr]
    for _ in range(4):  # 0.6 s after the flood: a kept bucket would hold 2.4 tokens, a fresh one 4
        src.handle_datagram(pose, PHONE, 0.7, 6000)
    assert len(src.drain()) == 4 and "rate limit" not in src.status().drop_reasons
