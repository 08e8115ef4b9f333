import struct

import numpy as np
import pytest

from input.codec import CodecError, decode_frame, encode_frame
from input.sample import TOUCH_DOWN, InputFrame, PoseSample


def _sample(**kw):
    base = {"time": 1.25, "source": "osc:127.0.0.1:5000", "orientation": [1.0, 0.0, 0.0, 0.0]}
    base.update(kw)
    return PoseSample(**base)


def test_sample_rejects_bad_values():
    with pytest.raises(ValueError, match="unit"):
        _sample(orientation=[2.0, 0, 0, 0])
    with pytest.raises(ValueError, match="finite"):
        _sample(position=[0.0, np.nan, 0.0])
    with pytest.raises(ValueError, match="3 values"):
        _sample(acceleration=[1.0, 2.0])
    with pytest.raises(ValueError, match="mode"):
        _sample(mode="screen")


@pytest.mark.parametrize(
    "field,value",
    [
        ("position", [1e308, 0.0, 0.0]),
        ("position", [0.0, -1001.0, 0.0]),
        ("angular_velocity", [0.0, 0.0, 1e5]),
        ("acceleration", [3000.0, 0.0, 0.0]),
        ("plane_normal", [0.0, 2.0, 0.0]),
        ("depth_delta", 1e308),
        ("orientation", [1e308, 0.0, 0.0, 0.0]),
    ],
)
def test_sample_rejects_finite_but_absurd_values(field, value):
    with pytest.raises(ValueError, match="range|unit"):
        _sample(**{field: value})


def test_a_recorded_sample_out_of_range_is_a_codec_error():
    good = encode_frame(InputFrame(frame=1, samples=(_sample(position=[1.0, 2.0, 3.0]),)))
    pos = good.index(struct.pack("<3d", 1.0, 2.0, 3.0))
    for bad in (1e308, float("nan"), float("inf")):
        data = good[:pos] + struct.pack("<d", bad) + good[pos + 8 :]
        with pytest.raises(CodecError, match="position"):
            decode_frame(data)
    q = good.index(struct.pack("<4d", 1.0, 0.0, 0.0, 0.0))
    with pytest.raises(CodecError, match="unit"):
        decode_frame(good[:q] + struct.pack("<d", float("nan")) + good[q + 8 :])


def test_frame_round_trip_is_bit_exact():
    rng = np.random.default_rng(1)
    q = rng.normal(size=4)
    s1 = _sample(
        orientation=q / np.linalg.norm(q),
        position=rng.normal(size=3),
        angular_velocity=rng.normal(size=3),
        acceleration=[0.1, 9.81, 0.3],
        touch=True,
        calibrate=True,
    )
    s2 = PoseSample(
        time=2.0,
        source="mouse",
        orientation=[1.0, 0, 0, 0],
        position=[0, 2, -4],
        mode="world",
        plane_normal=[0, 0, 1],
        depth_delta=-0.25,
        flick=True,
        touch=False,
    )
    f = InputFrame(frame=42, samples=(s1, s2), events=((TOUCH_DOWN, s1.source), ("connect", "mouse")))
    g = decode_frame(encode_frame(f))
    assert g.frame == 42 and g.events == f.events
    for a, b in zip(f.samples, g.samples, strict=True):
        for name in ("orientation", "position", "angular_velocity", "acceleration", "plane_normal"):
            va, vb = getattr(a, name), getattr(b, name)
            assert (va is None and vb is None) or va.tobytes() == vb.tobytes()
        assert (a.time, a.source, a.touch, a.mode, a.depth_delta, a.flick, a.calibrate) == (
            b.time,
            b.source,
            b.touch,
            b.mode,
            b.depth_delta,
            b.flick,
            b.calibrate,
        )
    assert encode_frame(g) == encode_frame(f)


def test_truncated_or_padded_frames_raise_codec_error():
    data = encode_frame(InputFrame(frame=3, samples=(_sample(touch=True),)))
    for cut in range(len(data)):
        with pytest.raises(CodecError):
            decode_frame(data[:cut])
    with pytest.raises(CodecError, match="trailing"):
        decode_frame(data + b"\0")


def test_latest_and_events_helpers():
    a, b = _sample(source="a"), _sample(source="b", time=3.0)
    f = InputFrame(samples=(a, b), events=((TOUCH_DOWN, "b"),))
    assert f.latest() is b and f.latest("a") is a and f.latest("c") is None
    assert f.has_event(TOUCH_DOWN, "b") and not f.has_event(TOUCH_DOWN, "a")
    assert f.sources() == ["a", "b"]
