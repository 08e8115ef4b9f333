"""The web message boundary at its exact limits, each error naming its field, and every optional
reading carried through (found uncovered by the mutation run, docs/mutation.md)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from input.web.protocol import (
    CROUCH_DEPTH,
    MAX_MESSAGE_BYTES,
    Ack,
    ControllerMessage,
    PageClock,
    WebMessageError,
    parse_message,
    to_sample_fields,
)

READING = {"seq": 3, "t": 1.7e12, "kind": "orientation", "o": [0.0, 0.0, 0.0]}
XR = {"seq": 1, "t": 0, "kind": "xr", "q": [0, 0, 0, 1], "p": [0.0, 0.0, 0.0]}


def _reason(fields: dict) -> str:
    with pytest.raises(WebMessageError) as err:
        parse_message(json.dumps(fields))
    return str(err.value)


def test_a_message_of_exactly_the_limit_is_read() -> None:
    text = json.dumps(READING)
    msg = parse_message(text + " " * (MAX_MESSAGE_BYTES - len(text)))
    assert isinstance(msg, ControllerMessage) and msg.seq == 3 and msg.t == 1.7e12


@pytest.mark.parametrize(
    ("fields", "ok", "bad", "reason"),
    [
        (READING, {"o": [360.0, -360.0, 0.0]}, {"o": [360.5, 0.0, 0.0]}, "o is out of range"),
        (XR, {"p": [1000.0, 0.0, -1000.0]}, {"p": [0.0, 1000.5, 0.0]}, "p is out of range"),
        (READING, {"acc": [2000.0, 0.0, 0.0]}, {"acc": [0.0, 0.0, 2000.5]}, "acc is out of range"),
        (READING, {"rot": [11000.0, 0.0, 0.0]}, {"rot": [0.0, 11000.5, 0.0]}, "rot is out of range"),
        (READING, {"seq": 0}, {"seq": 2**53}, "seq must be a whole number"),
        (READING, {"seq": 2**53 - 1}, {"seq": -1}, "seq must be a whole number"),
    ],
)
def test_each_limit_is_inclusive(fields: dict, ok: dict, bad: dict, reason: str) -> None:
    assert isinstance(parse_message(json.dumps({**fields, **ok})), ControllerMessage)
    assert _reason({**fields, **bad}) == reason


@pytest.mark.parametrize(
    ("fields", "reason"),
    [
        ({"ping": "now"}, "ping must be a number"),
        ({**READING, "t": "now"}, "t must be a number"),
        ({k: v for k, v in READING.items() if k != "t"}, "t must be a number"),
        ({**READING, "acc": [0, "x", 0]}, "acc must be a number"),
        ({**READING, "acc": [0, 0]}, "acc must be a list of 3 numbers"),
        ({**READING, "rot": [0, None, 0]}, "rot must be a number"),
        ({**READING, "jump": "yes"}, "jump must be true or false"),
        ({**READING, "cal": 0}, "cal must be true or false"),
        ({**READING, "a" * 30: 1}, "unknown field 'aaaaaaaaaaaaaaaaaaaa'"),  # cut to 20 characters
    ],
)
def test_each_error_names_its_field(fields: dict, reason: str) -> None:
    assert _reason(fields) == reason


def test_the_optional_readings_are_carried() -> None:
    msg = parse_message(json.dumps({**READING, "acc": [0.5, -9.8, 1.0], "rot": [0.0, 180.0, 0.0]}))
    assert isinstance(msg, ControllerMessage)
    assert msg.acceleration is not None and np.allclose(msg.acceleration, [0.5, -9.8, 1.0])
    assert msg.angular_velocity is not None and np.allclose(msg.angular_velocity, [np.pi, 0.0, 0.0])
    assert msg.kind == "orientation"
    plain = parse_message(json.dumps(READING))
    assert isinstance(plain, ControllerMessage)
    assert plain.acceleration is None and plain.angular_velocity is None and plain.crouch == 0.0
    assert not (plain.touch or plain.jump or plain.calibrate)


def test_an_xr_pose_keeps_its_position_in_the_sample_lowered_by_the_crouch() -> None:
    msg = parse_message(json.dumps({**XR, "p": [0.1, 1.2, -0.3], "crouch": 0.5}))
    assert isinstance(msg, ControllerMessage) and msg.kind == "xr"
    fields = to_sample_fields(msg, "web:1", 3.0)
    assert np.allclose(fields["position"], [0.1, 1.2 - 0.5 * CROUCH_DEPTH, -0.3])
    assert np.allclose(msg.position, [0.1, 1.2, -0.3])  # the reading itself is not changed


def test_the_page_clock_maps_page_times_by_the_least_delayed_reading() -> None:
    """Page times in ms; arrivals in s on the server's clock. The first reading sets the offset; a later,
    more delayed one is stamped at its page time (earlier than its arrival); a less delayed one lowers
    the offset; a page clock that jumps back or runs more than a second ahead restarts it."""
    clock = PageClock()
    assert clock.stamp(1000.0, 10.0) == pytest.approx(10.0)  # offset 9.0 s
    assert clock.stamp(1100.0, 10.3) == pytest.approx(10.1)  # 0.2 s more delay: stamped at 1.1 + 9.0
    assert clock.stamp(1200.0, 10.15) == pytest.approx(10.15)  # less delay: offset 8.95
    assert clock.offset == pytest.approx(8.95)
    assert clock.stamp(1300.0, 10.85) == pytest.approx(10.25)  # 0.6 s later than the offset: kept
    assert clock.stamp(-3.6e6, 11.0) == pytest.approx(11.0)  # the phone set its clock back an hour
    assert clock.offset == pytest.approx(3611.0)
    assert clock.stamp(-3.6e6 + 100.0, 11.1) == pytest.approx(11.1)
    assert clock.stamp(-3.6e6 + 200.0, 12.8) == pytest.approx(12.8)  # 1.6 s late: restarted


@pytest.mark.parametrize("step", [0, 1, 2**32 - 1])
def test_an_ack_carries_its_step(step: int) -> None:
    """The page's back-pressure message (fourth mutation round: no selected test parsed one)."""
    assert parse_message(json.dumps({"ack": step})) == Ack(step)


@pytest.mark.parametrize("step", [-1, 2**32, True, 1.5, "3", None])
def test_an_ack_that_is_not_a_step_number_is_refused(step: object) -> None:
    assert _reason({"ack": step}) == "ack must be a step number"


def test_an_ack_among_other_fields_is_not_an_ack() -> None:
    assert _reason({**READING, "ack": 3}) == "unknown field 'ack'"


def test_the_page_clock_keeps_a_reading_exactly_one_second_late() -> None:
    """The restart is for a page clock *more* than a second ahead (binary-exact times)."""
    clock = PageClock()
    assert clock.stamp(0.0, 10.0) == 10.0  # offset 10 s
    assert clock.stamp(1000.0, 12.0) == 11.0  # a second late: stamped at its page time, offset kept
    assert clock.offset == 10.0
