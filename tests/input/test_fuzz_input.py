"""Fuzzing the input boundary: OSC datagrams, serial streams, recorded frames and recordings.

Allowed outcomes: a valid sample (finite, in range: it passed ``check_sample_ranges``), nothing
(a counted drop), or the format's own error (``CodecError``, ``RecordingError``). Never another
exception, never a hang, never a large allocation (see ``Campaign`` in ``tests/conftest.py``).
"""

from __future__ import annotations

import json
import struct
import zlib
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from pythonosc.osc_bundle_builder import IMMEDIATELY, OscBundleBuilder
from pythonosc.osc_message_builder import OscMessageBuilder

from input.codec import CodecError, decode_frame, encode_frame
from input.osc import OscSource
from input.osc_profiles import OscDecoder
from input.recording import MAGIC, RecordingError, read_recording
from input.sample import InputFrame, PoseSample, check_sample_ranges
from input.serial_parse import SerialStreamParser

pytestmark = pytest.mark.fuzz

DATA = Path(__file__).resolve().parent.parent / "data"
ADDRESSES = [
    "/puppetphone/pose",
    "/puppetphone/orientation",
    "/puppetphone/touch",
    "/puppetphone/calibrate",
    "/puppetphone/gyro",
    "/puppetphone/accel",
    "/ZIGSIM/d/quaternion",
    "/ZIGSIM/d/arkitposition",
    "/ZIGSIM/d/arkitrotation",
    "/ZIGSIM/d/touch01",
    "/ZIGSIM/d/gyro",
    "/ZIGSIM/d/accel",
    "/rotationvector",
    "/pose6dof",
    "/touch1",
    "/gyroscope",
    "/accelerometer",
    "/accxyz",
    "/gyrosc/quat",
    "/gyrosc/gyro",
    "/gyrosc/rrate",
    "/gyrosc/accel",
    "/gyrosc/button",
    "/d/deviceinfo",
]

numbers = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True, width=32),
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(-(2**31), 2**31 - 1),
    st.sampled_from([0.0, 1.0, -1.0, 0.5, 1e308, -1e308, 5e-324]),
)
arguments = st.lists(st.one_of(numbers, st.text(max_size=8), st.booleans()), max_size=9)
messages = st.tuples(
    st.one_of(st.sampled_from(ADDRESSES), st.text(min_size=1, max_size=20).map(lambda a: "/" + a)), arguments
)


def _message(address: str, args: list[object]) -> OscMessageBuilder:
    b = OscMessageBuilder(address)
    for a in args:
        if isinstance(a, float) and abs(a) > 3e38:
            b.add_arg(a, "d")  # a float32 cannot hold it: send a double, as the attack did
        else:
            b.add_arg(a)
    return b


def _datagram(items: list[tuple[str, list[object]]], as_bundle: bool) -> bytes:
    if not as_bundle:
        return _message(*items[0]).build().dgram
    bb = OscBundleBuilder(IMMEDIATELY)
    for address, args in items:
        bb.add_content(_message(address, args).build())
    return bb.build().dgram


def _valid(sample: object) -> None:
    if sample is not None:
        assert isinstance(sample, PoseSample)
        check_sample_ranges(sample)


@pytest.fixture(scope="module")
def osc_source():
    src = OscSource(host="127.0.0.1", port=0, max_senders=4, admit_after=1, max_rate=1e9)
    yield src
    src.stop()


@given(st.lists(messages, min_size=1, max_size=6), st.booleans())
def test_fuzz_osc_messages_decode_to_valid_samples_or_drops(osc_source, items, as_bundle):
    try:
        data = _datagram(items, as_bundle)
    except Exception:  # python-osc's builder refuses some arguments (a str with NUL …): not our input
        return
    decoder = OscDecoder(on_drop=lambda reason, detail: None)
    for sender in ("a", "b"):
        _valid(decoder.decode(data, sender, 0.0))
    osc_source.handle_datagram(data, "osc:10.9.9.9", 0.0)
    for item in osc_source.drain():
        _valid(item if isinstance(item, PoseSample) else None)


def test_fuzz_osc_byte_mutations(campaign, mutations, fuzz_budget):
    seeds = [
        _datagram([("/puppetphone/pose", [0.1, 0.2, 0.3, 1.0, 0.0, 0.0, 0.0])], False),
        _datagram(
            [
                ("/ZIGSIM/d/quaternion", [0.0, 0.0, 0.0, 1.0]),
                ("/ZIGSIM/d/touch01", [0.1]),
                ("/ZIGSIM/d/gyro", [0.0, 0.5, 0.0]),
                ("/ZIGSIM/d/accel", [0.0, 0.0, 1.0]),
            ],
            True,
        ),
        _datagram([("/rotationvector", [0.0, 0.0, 0.0, 1.0, 0.1])], False),
    ]
    cases, seed = fuzz_budget(3000)
    c = campaign(())
    decoder = OscDecoder(on_drop=lambda reason, detail: None)
    decoded = 0
    for k, good in enumerate(seeds):
        for data in mutations(good, cases // len(seeds), seed + k):
            sample = c.run(decoder.decode, data, "m", 0.0)
            _valid(sample)
            decoded += sample is not None
    c.check("osc datagrams")
    print(f"{decoded} mutated datagrams decoded to a sample")
    assert decoded > 0, "no mutated datagram decoded: a decoder dropping everything would pass"


@given(
    st.lists(
        st.one_of(
            st.lists(numbers, min_size=1, max_size=9).map(lambda v: ",".join(repr(float(x)) for x in v)),
            st.lists(numbers, min_size=4, max_size=4).map(lambda v: "quat\t" + "\t".join(repr(float(x)) for x in v)),
            st.text(max_size=40),
        ),
        max_size=8,
    ),
    st.binary(max_size=64),
    st.integers(1, 64),
)
def test_fuzz_serial_streams_give_unit_readings(lines, noise, chunk):
    data = ("\r\n".join(lines) + "\n").encode("utf-8", "replace") + noise
    p = SerialStreamParser()
    out = []
    for i in range(0, len(data), chunk):
        out += p.feed(data[i : i + chunk])
    for r in out:
        q = np.array(r.quaternion)
        assert np.isfinite(q).all() and abs(np.linalg.norm(q) - 1.0) < 1e-9
        if r.position is not None:
            PoseSample(time=0.0, source="s", orientation=q, position=r.position)  # in range


def _frame() -> bytes:
    s = PoseSample(
        time=1.0,
        source="osc:10.0.0.1",
        orientation=[1.0, 0.0, 0.0, 0.0],
        position=[0.1, 1.2, -0.3],
        angular_velocity=[0.0, 1.0, 0.0],
        acceleration=[0.0, 9.8, 0.0],
        touch=True,
    )
    return encode_frame(InputFrame(frame=7, samples=(s, s), events=(("connect", "osc:10.0.0.1"),)))


def test_fuzz_recorded_frames(campaign, mutations, fuzz_budget):
    cases, seed = fuzz_budget(4000)
    c = campaign(CodecError)
    for data in mutations(_frame(), cases, seed):
        frame = c.run(decode_frame, data)
        if frame is not None:
            for s in frame.samples:
                check_sample_ranges(s)
    c.check("recorded frames")


def test_fuzz_recordings(campaign, mutations, fuzz_budget, tmp_path):
    good = (DATA / "puppet_jump_stop.rec").read_bytes()
    good = good[:1500]  # the header and the first records: enough structure, fast cases
    cases, seed = fuzz_budget(1500)
    c = campaign(RecordingError)
    path = tmp_path / "m.rec"
    for data in mutations(good, cases, seed):
        path.write_bytes(data)
        rec = c.run(read_recording, path)
        if rec is not None:
            for frame in rec.frames:
                for s in frame.samples:
                    check_sample_ranges(s)
    c.check("recordings")


@pytest.fixture(scope="module")
def header_path(tmp_path_factory):
    return tmp_path_factory.mktemp("headers") / "h.rec"


json_values = st.recursive(
    st.one_of(st.none(), st.booleans(), st.integers(-(2**70), 2**70), st.floats(allow_nan=True), st.text(max_size=10)),
    lambda inner: st.one_of(st.lists(inner, max_size=4), st.dictionaries(st.text(max_size=8), inner, max_size=4)),
    max_leaves=12,
)


@given(
    st.dictionaries(
        st.sampled_from(["game", "seed", "dt", "sources", "format", "engine_version", "extra", "other"]),
        json_values,
        max_size=8,
    ),
    st.fixed_dictionaries({"game": st.just("sandbox"), "seed": st.just(0), "dt": st.just(1 / 60)}),
)
def test_fuzz_recording_headers(header_path, fields, base):
    head = json.dumps({**base, **fields}).encode()
    path = header_path
    path.write_bytes(MAGIC + struct.pack("<II", len(head), zlib.crc32(head)) + head)
    try:
        rec = read_recording(path)
    except RecordingError:
        return
    h = rec.header
    assert isinstance(h.game, str) and isinstance(h.seed, int) and 1e-4 <= h.dt <= 1.0
