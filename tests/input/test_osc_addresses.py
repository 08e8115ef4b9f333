"""Every address the OSC decoder maps, decoded from real bytes into the field it feeds, and the
decoder's bookkeeping: what a drop's detail says, a bad message or packet not costing the good
ones, a rejected packet leaving its sender as it was, one-shot flags cleared after their sample.
(``test_osc_profiles.py`` covers each app's main path; these were found uncovered by the mutation run.)
"""

from __future__ import annotations

import logging

import numpy as np
import pytest

from engine import quat
from input import osc_profiles
from input.osc_profiles import G, OscDecoder
from input.phone_frames import arkit_to_stick, phone_to_stick

_X = np.array([1.0, 0.0, 0.0])
_Y = np.array([0.0, 1.0, 0.0])
_Z = np.array([0.0, 0.0, 1.0])


@pytest.fixture
def dec():  # type: ignore[no-untyped-def]
    drops: list[tuple[str, str]] = []
    d = OscDecoder(on_drop=lambda reason, detail: drops.append((reason, detail)))
    d.drops = drops  # type: ignore[attr-defined]
    return d


@pytest.mark.parametrize(
    ("address", "args", "field", "expected"),
    [
        ("/puppetphone/gyro", (0.1, 0.2, 0.3), "angular_velocity", [0.1, 0.2, 0.3]),
        ("/puppetphone/accel", (0.0, 9.0, 1.0), "acceleration", [0.0, 9.0, 1.0]),  # m/s²
        ("/gyroscope", (0.4, 0.0, -0.4), "angular_velocity", [0.4, 0.0, -0.4]),
        ("/accelerometer", (0.0, 0.0, 9.8), "acceleration", [0.0, 0.0, 9.8]),  # m/s²
        ("/gyrosc/rrate", (0.0, 1.5, 0.0), "angular_velocity", [0.0, 1.5, 0.0]),
        ("/gyrosc/accel", (0.0, 0.0, -1.0), "acceleration", [0.0, 0.0, -G]),  # g
        ("/ZIGSIM/d/accel", (0.5, 0.0, 0.0), "acceleration", [0.5 * G, 0.0, 0.0]),  # g
        ("/accxyz", (0.0, 0.0, -1.0), "acceleration", [0.0, 0.0, -G]),  # g
        ("/puppetphone/gyro", (1, 2, 3), "angular_velocity", [1.0, 2.0, 3.0]),  # OSC int32 arguments
    ],
)
def test_each_sensor_address_feeds_its_field_in_si_units(dec, osc, address, args, field, expected) -> None:  # type: ignore[no-untyped-def]
    message, _ = osc
    s = dec.decode(message(address, *args), "p", 0.0)
    assert s is not None, dec.drops
    got = getattr(s, field)
    assert got.dtype == np.float64 and np.allclose(got, expected)


def test_sensors2osc_pose6dof_is_a_z_up_position_and_an_attitude(dec, osc) -> None:  # type: ignore[no-untyped-def]
    """``/pose6dof`` x,y,z,w (attitude), then the position in a Z-up world, then up to 8 more values."""
    message, _ = osc
    q = quat.from_axis_angle(_X, 0.5)
    xyzw = [float(v) for v in quat.to_xyzw(q)]
    s = dec.decode(message("/pose6dof", *xyzw, 1.0, 2.0, 3.0), "s", 0.0)
    assert np.allclose(s.position, [1.0, 3.0, -2.0]) and np.allclose(s.orientation, phone_to_stick(q))
    s = dec.decode(message("/pose6dof", *xyzw, 4.0, 5.0, 6.0, *[0.0] * 8), "s", 0.1)
    assert np.allclose(s.position, [4.0, 6.0, -5.0])
    for n in (6, 16):
        assert dec.decode(message("/pose6dof", *(xyzw + [0.0] * 12)[:n]), "s", 0.2) is None
    assert [r for r, _ in dec.drops] == ["wrong arity", "wrong arity"]


def test_sensors2osc_rotation_takes_up_to_five_values() -> None:
    drops: list[str] = []
    dec = OscDecoder(on_drop=lambda r, d: drops.append(d))
    from pythonosc.osc_message_builder import OscMessageBuilder

    def msg(*args: float) -> bytes:
        b = OscMessageBuilder("/georotationvector")
        for a in args:
            b.add_arg(float(a))
        return b.build().dgram

    q = [float(v) for v in quat.to_xyzw(quat.from_axis_angle(_Z, 0.3))]
    s = dec.decode(msg(*q, 0.2), "s", 0.0)  # the fifth value is the accuracy
    assert np.allclose(s.orientation, phone_to_stick(quat.from_axis_angle(_Z, 0.3)))
    assert dec.decode(msg(*q, 0.2, 0.0), "s", 0.1) is None
    assert drops == ["/georotationvector: wrong arity: 6 arguments, expected 3..5"]


@pytest.mark.parametrize(
    ("x", "y", "down"),
    [(0.4, 0.6, True), (-1.0, 0.5, True), (0.5, -1.0, True), (0.0, -1.0, True), (-1.0, 0.0, True), (-1.0, -1.0, False)],
)
def test_sensors2osc_touch_is_up_only_at_minus_one_minus_one(dec, osc, x, y, down) -> None:  # type: ignore[no-untyped-def]
    message, _ = osc
    if not down:
        dec.decode(message("/touch1", 0.5, 0.5), "s", 0.0)
    assert dec.decode(message("/touch1", x, y), "s", 0.1).touch is down


def test_gyrosc_euler_angles_are_heading_then_pitch_then_roll(dec, osc) -> None:  # type: ignore[no-untyped-def]
    """``/gyrosc/gyro`` pitch, roll, yaw: the attitude is yaw about world Z-up, then pitch about the
    phone's X, then roll about its Y."""
    message, _ = osc
    pitch, roll, yaw = 0.3, 0.2, 0.5
    s = dec.decode(message("/gyrosc/gyro", pitch, roll, yaw), "g", 0.0)
    device = quat.mul(
        quat.mul(quat.from_axis_angle(_Z, yaw), quat.from_axis_angle(_X, pitch)), quat.from_axis_angle(_Y, roll)
    )
    assert np.allclose(s.orientation, phone_to_stick(device))
    assert dec.decode(message("/gyrosc/gyro", pitch, roll), "g", 0.1) is None


@pytest.mark.parametrize(("args", "down"), [((1.0,), True), ((0.0,), False), ((3.0, 1.0), True), ((1.0, 0.0), False)])
def test_gyrosc_button_state_is_its_last_value(dec, osc, args, down) -> None:  # type: ignore[no-untyped-def]
    message, _ = osc
    if not down:
        dec.decode(message("/gyrosc/button", 1.0), "g", 0.0)
    assert dec.decode(message("/gyrosc/button", *args), "g", 0.1).touch is down


def test_gyrosc_button_takes_one_or_two_values(dec, osc) -> None:  # type: ignore[no-untyped-def]
    message, _ = osc
    assert dec.decode(message("/gyrosc/button"), "g", 0.0) is None
    assert dec.decode(message("/gyrosc/button", 1.0, 1.0, 1.0), "g", 0.0) is None
    assert [d for _, d in dec.drops] == [
        "/gyrosc/button: wrong arity: 0 arguments, expected 1..2",
        "/gyrosc/button: wrong arity: 3 arguments, expected 1..2",
    ]


@pytest.mark.parametrize("address", ["/ZIGSIM/d/touchradius1", "/ZIGSIM/d/touchforce1", "/d/touch01"])
def test_zigsim_touch_radius_and_force_count_as_a_finger_down(dec, osc, address) -> None:  # type: ignore[no-untyped-def]
    _message, bundle = osc
    assert dec.decode(bundle((address, 0.5)), "z", 0.0).touch is True
    assert dec.decode(bundle((address, 0.5, 0.1, 0.2)), "z", 0.1).touch is False  # three values: not a finger
    assert dec.drops == [("wrong arity", f"{address}: wrong arity: 3 arguments, expected 1..2")]


def test_zigsim_gravity_is_ignored_silently(dec, osc) -> None:  # type: ignore[no-untyped-def]
    message, _ = osc
    assert dec.decode(message("/ZIGSIM/d/gravity", 0.0, 0.0, -1.0), "z", 0.0) is None
    assert dec.drops == []


def test_once_arkit_gives_the_attitude_coremotion_is_not_used(dec, osc) -> None:  # type: ignore[no-untyped-def]
    _, bundle = osc
    coremotion = [float(v) for v in quat.to_xyzw(quat.from_axis_angle(_X, 0.4))]
    s = dec.decode(
        bundle(("/ZIGSIM/d/arkitrotation", 0.0, 0.0, 0.0, 1.0), ("/ZIGSIM/d/quaternion", *coremotion)), "z", 0.0
    )
    assert np.allclose(s.orientation, arkit_to_stick([1.0, 0.0, 0.0, 0.0]))
    assert dec.decode(bundle(("/ZIGSIM/d/quaternion", *coremotion)), "z", 0.1) is None


# --- what a drop says, and what it costs --------------------------------------------------------


def test_the_drop_details_name_the_address_and_the_fault(dec, osc) -> None:  # type: ignore[no-untyped-def]
    message, _ = osc
    dec.decode(message("/puppetphone/orientation", 1.0, 0.0), "a", 0.0)
    dec.decode(message("/puppetphone/orientation", True, 0.0, 0.0, 0.0), "a", 0.0)
    dec.decode(message("/puppetphone/gyro", 0.0, 2e6, 0.0), "a", 0.0)
    dec.decode(b"garbage!", "a", 0.0)
    assert dec.drops[:3] == [
        ("wrong arity", "/puppetphone/orientation: wrong arity: 2 arguments, expected 4"),
        ("wrong type", "/puppetphone/orientation: wrong type: bool argument"),
        ("value out of range", "/puppetphone/gyro: value out of range (beyond 1e+06)"),
    ]
    reason, detail = dec.drops[3]
    assert reason == "malformed packet" and detail.startswith("ParseError: ")


def test_a_value_of_a_million_is_still_taken_as_a_number(dec, osc) -> None:  # type: ignore[no-untyped-def]
    """The range guard is *beyond* 1e6; the sample's own limits then judge it (an invalid sample here)."""
    message, _ = osc
    assert dec.decode(message("/puppetphone/gyro", 0.0, 1e6, 0.0), "a", 0.0) is None
    assert dec.drops[0][0] == "invalid sample"


def test_long_addresses_are_cut_in_the_detail(dec, osc) -> None:  # type: ignore[no-untyped-def]
    message, _ = osc
    dec.decode(message("/x" * 80, 1.0), "a", 0.0)
    dec.decode(message("/*" + "/x" * 80, 1.0), "a", 0.0)
    assert [(r, len(d)) for r, d in dec.drops] == [("unknown address", 100), ("address pattern", 100)]


def test_a_long_parse_error_is_cut_in_the_detail(dec) -> None:  # type: ignore[no-untyped-def]
    """python-osc quotes a bad type-tag string whole in its error; the detail keeps 200 characters.
    Broken by: the cut made 201 (mutmut ``decode__mutmut_10``)."""
    tag = b"x" * 400  # a type-tag string must start with ","
    dec.decode(b"/a\x00\x00" + tag + b"\x00" * 4, "a", 0.0)
    reason, detail = dec.drops[0]
    assert reason == "malformed packet" and len(detail) == 200 and detail.startswith("ParseError: ")


def test_a_pattern_or_an_unknown_address_does_not_cost_the_rest_of_the_bundle(dec, osc) -> None:  # type: ignore[no-untyped-def]
    _, bundle = osc
    s = dec.decode(
        bundle(
            ("/*/quaternion", 0.0, 0.0, 0.0, 1.0), ("/nobody/here", 1.0), ("/ZIGSIM/d/arkitposition", 1.0, 2.0, 3.0)
        ),
        "z",
        0.0,
    )
    assert s is not None and np.allclose(s.position, [1.0, 2.0, 3.0])
    assert [r for r, _ in dec.drops] == ["address pattern", "unknown address"]


def test_a_packet_out_of_range_leaves_its_sender_as_it_was(dec, osc) -> None:  # type: ignore[no-untyped-def]
    """Finite but beyond the sample's limits (a 5 km position): dropped whole, the sender's last pose kept;
    a new sender's first such packet does not create it."""
    message, _ = osc
    dec.decode(message("/puppetphone/pose", 0.1, 0.2, 0.3, 1.0, 0.0, 0.0, 0.0), "a", 0.0)
    assert dec.decode(message("/puppetphone/pose", 5000.0, 0.2, 0.3, 1.0, 0.0, 0.0, 0.0), "a", 0.1) is None
    assert dec.drops[0][0] == "invalid sample" and dec.drops[0][1].startswith("a: ")
    s = dec.decode(message("/puppetphone/touch", 1), "a", 0.2)
    assert np.allclose(s.position, [0.1, 0.2, 0.3])
    assert dec.decode(message("/puppetphone/pose", 5000.0, 0.2, 0.3, 1.0, 0.0, 0.0, 0.0), "b", 0.3) is None
    assert "b" not in dec.senders


def test_calibrate_is_in_one_sample_only(dec, osc) -> None:  # type: ignore[no-untyped-def]
    message, _ = osc
    assert dec.decode(message("/puppetphone/calibrate"), "a", 0.0).calibrate is True
    assert dec.decode(message("/puppetphone/touch", 1), "a", 0.1).calibrate is False


# --- python-osc's log lines ------------------------------------------------------------------------


def test_the_log_filter_is_installed_once_and_drops_only_python_osc_lines(monkeypatch: pytest.MonkeyPatch) -> None:
    root = logging.getLogger()
    monkeypatch.setattr(
        root, "filters", [f for f in root.filters if not isinstance(f, osc_profiles._PythonOscWarnings)]
    )
    OscDecoder(on_drop=lambda *a: None)
    OscDecoder(on_drop=lambda *a: None)
    ours = [f for f in root.filters if isinstance(f, osc_profiles._PythonOscWarnings)]
    assert len(ours) == 1
    inside = logging.LogRecord(
        "x", logging.WARNING, osc_profiles._PYTHONOSC_DIR + "/parsing/osc_types.py", 1, "m", None, None
    )
    outside = logging.LogRecord("x", logging.WARNING, "/somewhere/else.py", 1, "m", None, None)
    assert not ours[0].filter(inside) and ours[0].filter(outside)


def test_a_device_name_with_capitals_is_not_an_address_pattern(dec, osc) -> None:  # type: ignore[no-untyped-def]
    """ZIG SIM puts the device's name or id in the address: ``/XPHONE/quaternion`` is a reading."""
    message, _ = osc
    s = dec.decode(message("/XPHONE/quaternion", 0.0, 0.0, 0.0, 1.0), "z", 0.0)
    assert s is not None and dec.drops == []


def test_a_long_sender_name_is_cut_in_the_detail(dec, osc) -> None:  # type: ignore[no-untyped-def]
    message, _ = osc
    assert dec.decode(message("/puppetphone/gyro", 0.0, 500.0, 0.0), "s" * 300, 0.0) is None
    assert dec.drops[0][0] == "invalid sample" and len(dec.drops[0][1]) == 200
