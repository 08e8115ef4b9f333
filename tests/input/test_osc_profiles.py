"""Each app profile decoded from real OSC bytes; every kind of bad input counted, never raised."""

import math

import numpy as np
import pytest

from engine import quat
from input.osc_profiles import G, OscDecoder
from input.phone_frames import arkit_to_stick, phone_to_stick

Z = np.array([0.0, 0.0, 1.0])


@pytest.fixture
def dec():
    drops = []
    d = OscDecoder(on_drop=lambda r, detail: drops.append(r))
    d.drops = drops
    return d


def pitch_xyzw(angle):
    """A phone attitude pitched about its X axis, scalar last as apps send it."""
    return [float(v) for v in quat.to_xyzw(quat.from_axis_angle([1, 0, 0], angle))]


def test_own_scheme_pose_touch_calibrate(dec, osc):
    message, bundle = osc
    s = dec.decode(message("/puppetphone/pose", 0.1, 0.2, 0.3, 1.0, 0.0, 0.0, 0.0), "a", 1.0)
    assert np.allclose(s.position, [0.1, 0.2, 0.3]) and np.allclose(s.orientation, [1, 0, 0, 0]) and s.touch is None
    s = dec.decode(message("/puppetphone/touch", 1), "a", 1.1)
    assert s.touch is True and np.allclose(s.position, [0.1, 0.2, 0.3])  # a full pose every time
    s = dec.decode(message("/puppetphone/calibrate"), "a", 1.2)
    assert s.calibrate and not dec.decode(message("/puppetphone/touch", 1), "a", 1.3)  # nothing changed
    assert dec.drops == []


def test_zigsim_bundle_is_one_sample_with_touch_while_present(dec, osc):
    _, bundle = osc
    q = pitch_xyzw(0.4)
    s = dec.decode(
        bundle(
            ("/ZIGSIM/dev1/quaternion", *q),
            ("/ZIGSIM/dev1/touch01", 0.1),
            ("/ZIGSIM/dev1/touch02", -0.2),
            ("/ZIGSIM/dev1/gyro", 0.0, 0.5, 0.0),
            ("/ZIGSIM/dev1/accel", 0.0, 0.0, 1.0),
            ("/dev1/deviceinfo", "iPhone", "dev1", "ios", "17", 1170, 2532),
        ),
        "z",
        0.0,
    )
    assert s.touch is True
    expect = phone_to_stick(quat.from_xyzw(q))
    assert np.allclose(s.orientation, expect)
    assert np.allclose(s.angular_velocity, [0, 0.5, 0]) and np.allclose(s.acceleration, [0, 0, G])
    s = dec.decode(bundle(("/ZIGSIM/dev1/quaternion", *q)), "z", 0.1)
    assert s.touch is False  # no touch messages in this tick: the finger is up
    assert dec.drops == []


def test_zigsim_docs_prefix_and_arkit_six_dof(dec, osc):
    _, bundle = osc
    rot = [0.0, 0.0, 0.0, 1.0]
    s = dec.decode(
        bundle(
            ("/dev1/quaternion", *pitch_xyzw(0.2)),
            ("/dev1/arkitposition", 0.5, 1.2, -0.3),
            ("/dev1/arkitrotation", *rot),
        ),
        "z",
        0.0,
    )
    assert np.allclose(s.position, [0.5, 1.2, -0.3])
    assert np.allclose(s.orientation, arkit_to_stick([1.0, 0, 0, 0]))  # ARKit attitude wins over CoreMotion
    assert np.allclose(quat.rotate(s.orientation, Z), [0, 0, -1])  # the back camera looks along -Z


def test_sensors2osc_rotation_vector_and_touch(dec, osc):
    message, _ = osc
    q = pitch_xyzw(math.pi / 2)  # pointing the top edge at the sky
    s = dec.decode(message("/rotationvector", *q, 0.05), "s", 0.0)
    assert np.allclose(quat.rotate(s.orientation, Z), [0, 1, 0], atol=1e-6)
    assert dec.decode(message("/touch1", 0.4, 0.6), "s", 0.1).touch is True
    assert dec.decode(message("/touch1", -1.0, -1.0), "s", 0.2).touch is False
    s = dec.decode(message("/gamerotationvector", *q[:3]), "s", 0.3)  # w omitted: implied
    assert np.allclose(quat.rotate(s.orientation, Z), [0, 1, 0], atol=1e-6)
    assert dec.drops == []


def test_touchosc_accxyz_tilt(dec, osc):
    message, _ = osc
    flat = dec.decode(message("/accxyz", 0.0, 0.0, -1.0), "t", 0.0)  # iOS flat on the table
    assert np.allclose(quat.rotate(flat.orientation, Z), [0, 0, -1], atol=1e-6)
    up = dec.decode(message("/accxyz", 0.0, -1.0, 0.0), "t", 0.1)  # standing on its bottom edge
    assert np.allclose(quat.rotate(up.orientation, Z), [0, 1, 0], atol=1e-6)


def test_gyrosc_quaternion_order_is_configurable(osc):
    message, _ = osc
    q = quat.from_axis_angle([1, 0, 0], 0.7)
    wxyz = OscDecoder(on_drop=lambda *a: None).decode(message("/gyrosc/quat", *map(float, q)), "g", 0.0)
    xyzw = OscDecoder(on_drop=lambda *a: None, gyrosc_order="xyzw").decode(
        message("/gyrosc/quat", *map(float, quat.to_xyzw(q))), "g", 0.0
    )
    assert np.allclose(wxyz.orientation, xyzw.orientation)
    with pytest.raises(ValueError):
        OscDecoder(on_drop=lambda *a: None, gyrosc_order="wxyy")


@pytest.mark.parametrize(
    "packet,reason",
    [
        (b"garbage!", "malformed packet"),
        (b"", "malformed packet"),
        ("trunc", "malformed packet"),
        (("/puppetphone/orientation", float("nan"), 0.0, 0.0, 0.0), "non-finite value"),
        (("/puppetphone/orientation", float("inf"), 0.0, 0.0, 0.0), "non-finite value"),
        (("/puppetphone/orientation", "one", 0.0, 0.0, 0.0), "wrong type"),
        (("/puppetphone/orientation", 1.0, 0.0), "wrong arity"),
        (("/puppetphone/orientation", 2.0, 0.0, 0.0, 0.0), "non-unit quaternion"),
        (("/ZIGSIM/x/quaternion", 0.0, 0.0, 0.0, 0.0), "non-unit quaternion"),
        (("/nobody/sends/this", 1.0), "unknown address"),
        (("/*/quaternion", 0.0, 0.0, 0.0, 1.0), "address pattern"),
    ],
)
def test_bad_input_is_dropped_with_a_reason(dec, osc, packet, reason):
    message, _ = osc
    if packet == "trunc":
        packet = message("/puppetphone/pose", 0.1, 0.2, 0.3, 1.0, 0.0, 0.0, 0.0)[:-6]
    elif isinstance(packet, tuple):
        packet = message(*packet)
    assert dec.decode(packet, "x", 0.0) is None
    assert dec.drops == [reason]


def test_a_bad_message_in_a_bundle_does_not_lose_the_good_ones(dec, osc):
    _, bundle = osc
    s = dec.decode(
        bundle(("/ZIGSIM/d/quaternion", float("nan"), 0.0, 0.0, 1.0), ("/ZIGSIM/d/arkitposition", 1.0, 2.0, 3.0)),
        "z",
        0.0,
    )
    assert np.allclose(s.position, [1, 2, 3]) and dec.drops == ["non-finite value"]


def test_garbage_type_tags_and_bundle_elements_print_nothing(dec, capfd, caplog):
    """python-osc logs a warning per odd packet (1,413 lines under garbage); none reach the terminal."""
    import logging

    caplog.set_level(logging.WARNING)
    odd_message = b"/puppetphone/pose\x00\x00\x00,X\x00\x00\x00\x00\x00\x00"
    odd_bundle = b"#bundle\x00" + b"\x00" * 8 + (8).to_bytes(4, "big") + b"garbage!"
    for i in range(50):
        dec.decode(odd_message, "a", float(i))
        dec.decode(odd_bundle, "a", float(i))
    out, err = capfd.readouterr()
    assert out == "" and err == "" and not [r for r in caplog.records if "pythonosc" in r.pathname]
    assert dec.drops  # what was dropped is counted instead
