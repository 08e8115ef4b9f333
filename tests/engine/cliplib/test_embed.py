"""Clips in a game's set-up: exact round trip through JSON, tampering refused."""

from __future__ import annotations

import copy
import hashlib
import json

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from engine.cliplib.embed import decode, encode
from engine.cliplib.library import ClipLibraryError, clip_digest
from engine.clips import default_clips
from engine.humanoid import humanoid_skeleton

SK = humanoid_skeleton()


def test_round_trip_is_bit_exact() -> None:
    clips = {k: default_clips()[k] for k in ("walk", "get_up")}
    value = json.loads(json.dumps(encode(clips)))
    back = decode(value, SK)
    assert {k: clip_digest(v) for k, v in back.items()} == {k: clip_digest(v) for k, v in clips.items()}
    assert np.array_equal(back["walk"].rotations, clips["walk"].rotations)
    assert len(json.dumps(value)) < 200_000  # a few tens of KB in a recording's header


def test_tampering_is_refused() -> None:
    value = encode({"walk": default_clips()["walk"]})
    other = copy.deepcopy(value)
    other["clips"]["walk"]["markers"]["left_down"] = 0.25
    with pytest.raises(ClipLibraryError, match="do not match their hash"):
        decode(other, SK)
    for key, bad, reason in (("frames", 10, "bytes of data"), ("data", "!!", "not base64"), ("fps", 0, "fps")):
        other = copy.deepcopy(value)
        other["clips"]["walk"][key] = bad
        other["sha256"] = hashlib.sha256(json.dumps(other["clips"], sort_keys=True).encode()).hexdigest()
        with pytest.raises(ClipLibraryError, match=reason):
            decode(other, SK)


@given(
    st.dictionaries(
        st.sampled_from(["name", "fps", "loop", "frames", "root_motion", "markers", "data"]),
        st.none()
        | st.booleans()
        | st.integers(-5, 10**6)
        | st.floats()
        | st.text(max_size=20)
        | st.dictionaries(st.text(max_size=5), st.floats(), max_size=3),
    )
)
def test_fuzz_decode(entry: dict) -> None:
    base = encode({"walk": default_clips()["walk"]})["clips"]["walk"]
    clips = {"walk": {**base, **entry}}
    value = {"sha256": hashlib.sha256(json.dumps(clips, sort_keys=True).encode()).hexdigest(), "clips": clips}
    try:
        out = decode(value, SK)  # checked past the hash: each field's own check
    except ClipLibraryError as exc:
        assert "\n" not in str(exc)
    else:
        assert np.isfinite(out["walk"].rotations).all()
