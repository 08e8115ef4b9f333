"""The OSC source's gate, driven datagram by datagram on a fake clock (no socket traffic, no sleeps).

Admission, lock-out, the token bucket, per-step budgets, bundle limits and expiry, each at its
boundary. Checked by mutation (docs/mutation.md): e.g. admitting after ``admit_after - 1`` samples
fails ``test_a_candidate_is_admitted_after_exactly_admit_after_valid_samples``; a bucket refilled
at twice the rate fails ``test_the_rate_limit_is_a_token_bucket_refilled_at_max_rate``.
"""

from __future__ import annotations

from collections.abc import Callable

import pytest

from input.osc import (
    ADMIT_AFTER,
    CANDIDATE_BUDGET,
    MAX_BUNDLE_DEPTH,
    MAX_CANDIDATES,
    MAX_DATAGRAM,
    MAX_MESSAGES,
    STEP_BUDGET,
    OscSource,
    bundle_shape,
)
from input.sample import CONNECT, DISCONNECT, PoseSample

Message = Callable[..., bytes]
PHONE, OTHER = "osc:10.0.0.1", "osc:10.0.0.2"


def nested(depth: int, inner: bytes) -> bytes:
    """``inner`` wrapped in ``depth`` bundles."""
    for _ in range(depth):
        inner = b"#bundle\x00" + b"\x00" * 8 + len(inner).to_bytes(4, "big") + inner
    return inner


def flat(n: int, msg: bytes) -> bytes:
    return b"#bundle\x00" + b"\x00" * 8 + b"".join(len(msg).to_bytes(4, "big") + msg for _ in range(n))


def samples(items: list[PoseSample | tuple[str, str]]) -> list[PoseSample]:
    return [i for i in items if isinstance(i, PoseSample)]


def test_bundle_shape_counts_messages_and_refuses_only_past_the_limits(pose: bytes) -> None:
    assert bundle_shape(pose) == (1, "")
    assert bundle_shape(b"") == (1, "")
    assert bundle_shape(flat(3, pose)) == (3, "")
    assert bundle_shape(nested(MAX_BUNDLE_DEPTH, pose)) == (1, "")
    assert bundle_shape(nested(MAX_BUNDLE_DEPTH + 1, pose)) == (0, "bundle too deep")
    assert bundle_shape(flat(MAX_MESSAGES, pose)) == (MAX_MESSAGES, "")
    assert bundle_shape(flat(MAX_MESSAGES + 1, pose))[1] == "bundle too large"
    assert bundle_shape(flat(2, flat(2, pose))) == (4, "")
    # a size field of zero, negative or past the end ends the walk (python-osc reports the rest)
    assert bundle_shape(b"#bundle\x00" + b"\x00" * 8 + (0).to_bytes(4, "big") + pose) == (0, "")
    assert bundle_shape(b"#bundle\x00" + b"\x00" * 8 + (len(pose) + 1).to_bytes(4, "big") + pose) == (0, "")
    assert bundle_shape(b"#bundle\x00" + b"\x00" * 8 + len(pose).to_bytes(4, "big") + pose + b"\x00\x00\x00") == (1, "")
    assert bundle_shape(b"#bundle\x00" + b"\x00" * 8 + b"\xff\xff\xff\xff" + pose) == (0, "")


def test_constructor_refuses_impossible_settings(source: Callable[..., OscSource]) -> None:
    with pytest.raises(ValueError, match="at least 1 .* not 0"):
        source(max_senders=0)
    with pytest.raises(ValueError, match="^admit_after must be at least 1, not 0$"):
        source(admit_after=0)
    for port in (-1, 65536):
        with pytest.raises(ValueError, match=f"^OSC port must be 0..65535, not {port}$"):
            OscSource(port=port)
    src = source(max_senders=1, admit_after=1)
    assert src.port > 0 and src.name == f"osc 127.0.0.1:{src.port}" and src.status().name == src.name
    assert not src.status().connected


def test_a_candidate_is_admitted_after_exactly_admit_after_valid_samples(
    source: Callable[..., OscSource], pose: bytes
) -> None:
    src = source()
    for i in range(ADMIT_AFTER - 1):
        src.handle_datagram(pose, PHONE, i / 60, 5000)
        assert src.drain() == []
    assert src.status().drop_reasons == {"sender pending": ADMIT_AFTER - 1}
    src.handle_datagram(b"garbage", PHONE, 0.5, 5000)  # garbage does not count towards admission
    assert src.drain() == []
    src.handle_datagram(pose, PHONE, 0.6, 5000)
    items = src.drain()
    assert items[0] == (CONNECT, PHONE) and len(samples(items)) == 1 and src.status().connected
    src.handle_datagram(pose, PHONE, 0.7, 5000)
    assert len(samples(src.drain())) == 1  # connected once: no second CONNECT
    src.handle_datagram(b"garbage", PHONE, 0.8, 5000)
    assert src.drain() == []


def test_admission_takes_the_slots_and_locks_the_rest_out(source: Callable[..., OscSource], pose: bytes) -> None:
    src = source(max_senders=1, admit_after=2)
    src.handle_datagram(pose, OTHER, 0.0, 7000)  # a candidate that will lose the race
    src.handle_datagram(pose, PHONE, 0.0, 5000)
    src.handle_datagram(pose, PHONE, 0.01, 5000)
    assert (CONNECT, PHONE) in src.drain()
    src.handle_datagram(pose, OTHER, 0.02, 7000)  # its candidacy ended when the slot was taken
    assert src.drain() == [] and src.status().locked_out == [OTHER]
    for k in range(5):
        src.handle_datagram(pose, f"osc:10.0.1.{k}", 0.03, 7000)
    src.handle_datagram(pose, "osc:10.0.1.4", 0.04, 7000)
    status = src.status()
    assert status.locked_out == [f"osc:10.0.1.{k}" for k in range(1, 5)]  # the latest four, once each
    assert status.drop_reasons["other sender"] == 7
    assert status.last_error == f"other sender: osc:10.0.1.4 (locked to {PHONE})"


def test_two_slots_take_two_phones(source: Callable[..., OscSource], pose: bytes) -> None:
    src = source(max_senders=2, admit_after=1)
    src.handle_datagram(pose, PHONE, 0.0, 5000)
    src.handle_datagram(pose, OTHER, 0.0, 5000)
    src.handle_datagram(pose, "osc:10.0.0.3", 0.0, 5000)
    items = src.drain()
    assert (CONNECT, PHONE) in items and (CONNECT, OTHER) in items and len(samples(items)) == 2
    assert src.status().locked_out == ["osc:10.0.0.3"]


def test_candidates_are_bounded(source: Callable[..., OscSource], pose: bytes) -> None:
    src = source(admit_after=5)
    for k in range(MAX_CANDIDATES + 1):
        src.handle_datagram(pose, f"osc:10.0.2.{k}", 0.0, 5000)
    assert src.status().drop_reasons.get("too many senders") == 1
    assert src.status().last_error == f"too many senders: osc:10.0.2.{MAX_CANDIDATES}"


def test_the_rate_limit_is_a_token_bucket_refilled_at_max_rate(source: Callable[..., OscSource], pose: bytes) -> None:
    src = source(max_rate=10.0, admit_after=1)
    for _k in range(10):  # a full bucket: ten at once
        src.handle_datagram(pose, PHONE, 0.0, 5000)
        src.drain()
    src.handle_datagram(pose, PHONE, 0.0, 5000)
    assert src.status().drop_reasons == {"rate limit": 1}
    src.drain()
    src.handle_datagram(pose, PHONE, 0.05, 5000)  # half a token refilled: still empty
    assert src.status().drop_reasons == {"rate limit": 2}
    src.handle_datagram(pose, PHONE, 0.15, 5000)  # 0.5 + 1.0 tokens: one goes through
    assert len(samples(src.drain())) == 1
    src.handle_datagram(pose, PHONE, 0.20, 5000)  # 0.5 + 0.5
    assert len(samples(src.drain())) == 1
    src.handle_datagram(pose, PHONE, 100.0, 5000)  # a long pause refills to the cap, not beyond
    src.drain()
    passed = 0
    for _ in range(12):
        src.handle_datagram(pose, PHONE, 100.0, 5000)
        passed += len(samples(src.drain()))
    assert passed == 9


def test_an_admitted_sender_has_a_step_budget_renewed_by_drain(source: Callable[..., OscSource], pose: bytes) -> None:
    src = source(admit_after=1)
    src.handle_datagram(pose, PHONE, 0.0, 5000)
    src.drain()
    datagrams, messages, size = STEP_BUDGET
    for _ in range(datagrams):
        src.handle_datagram(pose, PHONE, 0.001, 5000)
    src.handle_datagram(pose, PHONE, 0.001, 5000)
    assert len(samples(src.drain())) == datagrams and src.status().drop_reasons == {"over budget": 1}
    big = flat(messages, pose)
    src.handle_datagram(big, PHONE, 0.002, 5000)
    src.handle_datagram(pose, PHONE, 0.002, 5000)  # the message budget is spent
    assert src.status().drop_reasons == {"over budget": 2}
    src.drain()
    src.handle_datagram(flat(messages + 1, pose), PHONE, 0.003, 5000)
    assert src.status().drop_reasons == {"over budget": 2, "bundle too large": 1}
    assert size == MAX_DATAGRAM


def test_byte_budgets_and_the_datagram_size_limit(source: Callable[..., OscSource], pose: bytes) -> None:
    src = source(admit_after=2)
    d_cand, m_cand, b_cand = CANDIDATE_BUDGET
    pad = flat(1, pose)
    filler = pad + b"\x00" * (b_cand - len(pad))  # exactly the candidate's byte budget, one message
    src.handle_datagram(filler, PHONE, 0.0, 5000)
    src.handle_datagram(pose, PHONE, 0.0, 5000)
    assert src.status().drop_reasons == {"sender pending": 1, "over budget": 1}
    src.drain()
    src.handle_datagram(b"\x00" * (MAX_DATAGRAM + 1), PHONE, 0.01, 5000)
    assert src.status().drop_reasons["oversize packet"] == 1
    assert src.status().last_error == f"oversize packet: {PHONE}: {MAX_DATAGRAM + 1} bytes"
    src.handle_datagram(nested(MAX_BUNDLE_DEPTH + 1, pose), PHONE, 0.02, 5000)
    assert src.status().drop_reasons["bundle too deep"] == 1
    assert d_cand == 2 and m_cand == 16


def test_a_candidate_has_the_smaller_budget(source: Callable[..., OscSource], pose: bytes) -> None:
    src = source(admit_after=10)
    for _ in range(CANDIDATE_BUDGET[0] + 1):
        src.handle_datagram(pose, PHONE, 0.0, 5000)
    assert src.status().drop_reasons == {"sender pending": CANDIDATE_BUDGET[0], "over budget": 1}
    src.drain()
    src.handle_datagram(flat(CANDIDATE_BUDGET[1] + 1, pose), PHONE, 0.01, 5000)
    assert src.status().drop_reasons["over budget"] == 2


def test_the_admitting_datagram_starts_the_full_budget(source: Callable[..., OscSource], pose: bytes) -> None:
    src = source(admit_after=2)
    src.handle_datagram(pose, PHONE, 0.0, 5000)
    src.handle_datagram(pose, PHONE, 0.0, 5000)  # admitted with the candidate budget spent
    for _ in range(STEP_BUDGET[0]):
        src.handle_datagram(pose, PHONE, 0.001, 5000)
    assert len(samples(src.drain())) == 1 + STEP_BUDGET[0]
    assert "over budget" not in src.status().drop_reasons


def test_other_ports_of_an_admitted_phone_have_their_own_bucket_and_budget(
    source: Callable[..., OscSource], pose: bytes
) -> None:
    src = source(admit_after=1, max_rate=4.0, timeout=1.0)
    src.handle_datagram(pose, PHONE, 0.0, 5000)
    src.drain()
    for _ in range(4):
        src.handle_datagram(b"garbage", PHONE, 0.9, 6000)
    src.handle_datagram(b"garbage", PHONE, 0.9, 6001)
    assert src.status().drop_reasons.get("rate limit") == 1
    assert src.status().last_error == f"rate limit: {PHONE}:6001"
    src._expire(1.5)  # garbage from other ports kept nothing alive: 1.5 s since the phone's own datagram
    assert (DISCONNECT, PHONE) in src.drain()


def test_a_valid_pose_from_another_port_is_the_phones_and_keeps_it_alive(
    source: Callable[..., OscSource], pose: bytes
) -> None:
    src = source(admit_after=1, timeout=1.0)
    src.handle_datagram(pose, PHONE, 0.0, 5000)
    src.drain()
    src.handle_datagram(pose, PHONE, 0.9, 6000)
    assert len(samples(src.drain())) == 1
    src._expire(1.5)
    assert src.drain() == []  # seen at 0.9 s
    for _ in range(STEP_BUDGET[0]):
        src.handle_datagram(pose, PHONE, 1.0, 6000 + _)
    src.handle_datagram(pose, PHONE, 1.0, 6100)
    assert src.status().drop_reasons == {"over budget": 1}
    src.handle_datagram(pose, PHONE, 1.0, 5000)  # the phone's own port still has all of its budget
    assert len(samples(src.drain())) == STEP_BUDGET[0] + 1


def test_quiet_senders_expire_after_the_timeout(source: Callable[..., OscSource], pose: bytes) -> None:
    src = source(admit_after=1, timeout=2.0)
    src.handle_datagram(pose, PHONE, 0.0, 5000)
    src.drain()
    src._expire(2.0)
    assert src.drain() == []  # exactly the timeout: still there
    src._expire(2.01)
    assert src.drain() == [(DISCONNECT, PHONE)] and not src.status().connected
    src.handle_datagram(pose, OTHER, 2.1, 5000)  # the slot is free again
    assert (CONNECT, OTHER) in src.drain()
    cand = source(admit_after=3, timeout=1.0)
    cand.handle_datagram(pose, PHONE, 0.0, 5000)
    cand.handle_datagram(pose, PHONE, 0.5, 5000)
    cand.drain()  # the next step: a fresh candidate budget
    cand._expire(1.49)
    cand.handle_datagram(pose, PHONE, 1.49, 5000)  # the third valid sample within the timeout: admitted
    assert (CONNECT, PHONE) in cand.drain()
    late = source(admit_after=2, timeout=1.0)
    late.handle_datagram(pose, PHONE, 0.0, 5000)
    late._expire(1.01)  # forgotten: its count starts again
    late.handle_datagram(pose, PHONE, 1.02, 5000)
    assert late.drain() == []
    late.handle_datagram(pose, PHONE, 1.03, 5000)
    assert (CONNECT, PHONE) in late.drain()
