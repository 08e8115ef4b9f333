"""The web controller's message boundary: readings become stick orientations; anything else is one clear error."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from engine import quat
from input.sample import PoseSample, check_sample_ranges
from input.web.protocol import (
    CROUCH_DEPTH,
    MAX_MESSAGE_BYTES,
    ControllerMessage,
    Ping,
    WebMessageError,
    orientation_to_quat,
    parse_message,
    to_sample_fields,
)

READING = {"seq": 3, "t": 1.7e12, "kind": "orientation", "o": [0.0, 0.0, 0.0], "touch": True}
FORWARD = np.array([0.0, 0.0, 1.0])


def _direction(msg: ControllerMessage) -> np.ndarray:
    return quat.rotate(msg.orientation, FORWARD)


def test_flat_phone_points_north_and_tilting_up_raises_the_stick():
    flat = parse_message(json.dumps(READING))
    assert isinstance(flat, ControllerMessage) and flat.touch and not flat.jump
    # Lying flat, top edge north: the stick is horizontal along north (engine -Z: Z-up Y becomes -Z).
    assert np.allclose(_direction(flat), [0.0, 0.0, -1.0], atol=1e-9)
    up = parse_message(json.dumps({**READING, "o": [0.0, 30.0, 0.0]}))
    assert np.allclose(_direction(up), [0.0, np.sin(np.radians(30)), -np.cos(np.radians(30))], atol=1e-9)
    # alpha turns the heading counter-clockwise seen from above (towards west = engine -X).
    west = parse_message(json.dumps({**READING, "o": [90.0, 0.0, 0.0]}))
    assert np.allclose(_direction(west), [-1.0, 0.0, 0.0], atol=1e-9)


def test_orientation_matches_the_w3c_matrix():
    a, b, g = np.radians([40.0, 25.0, -70.0])
    ca, sa, cb, sb, cg, sg = np.cos(a), np.sin(a), np.cos(b), np.sin(b), np.cos(g), np.sin(g)
    rz = np.array([[ca, -sa, 0], [sa, ca, 0], [0, 0, 1]])
    rx = np.array([[1, 0, 0], [0, cb, -sb], [0, sb, cb]])
    ry = np.array([[cg, 0, sg], [0, 1, 0], [-sg, 0, cg]])
    assert np.allclose(quat.to_matrix(orientation_to_quat(40.0, 25.0, -70.0)), rz @ rx @ ry, atol=1e-12)


def test_xr_pose_is_a_camera_pose_with_position():
    msg = parse_message(json.dumps({"seq": 1, "t": 0, "kind": "xr", "q": [0, 0, 0, 1], "p": [0.1, 1.2, -0.3]}))
    assert isinstance(msg, ControllerMessage)
    assert np.allclose(_direction(msg), [0.0, 0.0, -1.0], atol=1e-9)  # the viewer looks along -Z
    assert np.allclose(msg.position, [0.1, 1.2, -0.3])


def test_sample_fields_carry_buttons_crouch_and_motion():
    msg = parse_message(
        json.dumps({**READING, "jump": True, "cal": True, "crouch": 0.5, "acc": [0, 0, 9.8], "rot": [90.0, 0.0, 0.0]})
    )
    assert isinstance(msg, ControllerMessage)
    sample = PoseSample(**to_sample_fields(msg, "web:1", 12.5))
    assert sample.flick and sample.calibrate and sample.touch and sample.mode == "device"
    assert np.allclose(sample.position, [0.0, -0.5 * CROUCH_DEPTH, 0.0])
    assert np.allclose(sample.angular_velocity, [0.0, 0.0, np.pi / 2])  # alpha rate is about device z
    assert sample.time == 12.5 and sample.source == "web:1"


def test_ping():
    assert parse_message('{"ping": 12.5}') == Ping(12.5)


@pytest.mark.parametrize(
    ("text", "reason"),
    [
        (b"\x00\x01", "binary message"),
        ("x" * (MAX_MESSAGE_BYTES + 1), "message too long"),
        ("{not json", "not JSON"),
        ("[1, 2]", "not a JSON object"),
        (json.dumps({**READING, "evil": 1}), "unknown field 'evil'"),
        (json.dumps({**READING, "seq": -1}), "seq must be a whole number"),
        (json.dumps({**READING, "seq": True}), "seq must be a whole number"),
        (json.dumps({**READING, "kind": "teleport"}), "kind must be one of orientation, xr"),
        (json.dumps({**READING, "o": [0, 0]}), "o must be a list of 3 numbers"),
        (json.dumps({**READING, "o": [0, "1", 0]}), "o must be a number"),
        ('{"seq": 1, "t": 0, "kind": "orientation", "o": [0, NaN, 0]}', "o is out of range"),
        (json.dumps({**READING, "o": [0, 1e300, 0]}), "o is out of range"),
        (json.dumps({**READING, "touch": 1}), "touch must be true or false"),
        (json.dumps({**READING, "crouch": 2}), "crouch is out of range"),
        (json.dumps({**READING, "crouch": -0.1}), "crouch is out of range"),
        (json.dumps({"seq": 1, "t": 0, "kind": "xr", "q": [0, 0, 0, 2], "p": [0, 0, 0]}), "q is out of range"),
        (
            json.dumps({"seq": 1, "t": 0, "kind": "xr", "q": [0, 0, 0.5, 0.5], "p": [0, 0, 0]}),
            "q is not a unit quaternion",
        ),
        (json.dumps({"seq": 1, "t": 0, "kind": "xr", "q": [0, 0, 0, 1], "p": [0, 0, 5000]}), "p is out of range"),
        ("[" * 5000 + "]" * 5000, "message too long"),
    ],
)
def test_bad_messages_are_one_line_errors(text, reason):
    with pytest.raises(WebMessageError) as err:
        parse_message(text)
    assert str(err.value) == reason


json_values = st.recursive(
    st.one_of(
        st.none(),
        st.booleans(),
        st.integers(-(2**60), 2**60),
        st.floats(allow_nan=True, allow_infinity=True),
        st.text(max_size=6),
    ),
    lambda inner: st.lists(inner, max_size=5) | st.dictionaries(st.text(max_size=6), inner, max_size=4),
    max_leaves=12,
)
keys = st.sampled_from(["seq", "t", "kind", "o", "q", "p", "acc", "rot", "touch", "jump", "cal", "crouch", "ping"])


@pytest.mark.fuzz
@given(
    st.dictionaries(
        keys,
        st.one_of(
            json_values, st.sampled_from(["orientation", "xr"]), st.lists(st.floats(-400, 400), min_size=3, max_size=4)
        ),
        max_size=12,
    )
)
def test_fuzz_messages_give_valid_samples_or_one_error(fields):
    try:
        text = json.dumps(fields)
    except ValueError:
        return
    try:
        msg = parse_message(text)
    except WebMessageError as exc:
        assert "\n" not in str(exc)
        return
    if isinstance(msg, ControllerMessage):
        check_sample_ranges(PoseSample(**to_sample_fields(msg, "web:1", 0.0)))


@pytest.mark.fuzz
def test_fuzz_byte_mutations_of_a_reading(campaign, mutations, fuzz_budget):
    cases, seed = fuzz_budget(3000)
    c = campaign(WebMessageError)
    good = json.dumps({**READING, "acc": [0.1, 0.2, 9.8], "rot": [1.0, 2.0, 3.0], "crouch": 0.25}).encode()
    for data in mutations(good, cases, seed):
        text = data.decode("utf-8", errors="replace")
        msg = c.run(parse_message, text)
        if isinstance(msg, ControllerMessage):
            check_sample_ranges(PoseSample(**to_sample_fields(msg, "web:1", 0.0)))
    print(c.report("web readings"))
