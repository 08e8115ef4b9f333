"""Fuzzing what issue 24 added to the readers: ``--joint-map`` files, BVH frame blocks with counts
that disagree, and a ``.ppclip`` v2 with translation and scale channels.

Allowed outcomes: a value whose numbers are finite, or the format's own error
(``MotionFileError``, ``BvhError``, ``ClipFileError``); never another exception.
"""

from __future__ import annotations

import json
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from engine.clipfile import ClipFileError, load_clip, save_clip
from engine.clips import default_clips
from engine.io.bvh import BvhError, BvhWarning, parse_bvh
from engine.io.motion_file import MotionFileError, load_joint_map
from tests.engine.io.synthetic_bvh import human_bvh

pytestmark = pytest.mark.fuzz

_json = st.recursive(
    st.one_of(
        st.none(),
        st.booleans(),
        st.integers(),
        st.floats(),
        st.text(max_size=12),
        st.sampled_from(["hips", "l_foot", "head", "tail"]),
    ),
    lambda inner: st.one_of(st.lists(inner, max_size=4), st.dictionaries(st.text(max_size=8), inner, max_size=5)),
    max_leaves=12,
)


@settings(max_examples=150, deadline=None)
@given(_json)
def test_fuzz_joint_map_files(tmp_path_factory: pytest.TempPathFactory, value: object) -> None:
    path = tmp_path_factory.mktemp("m") / "map.json"
    path.write_text(json.dumps(value))
    try:
        out = load_joint_map(path)
    except MotionFileError:
        return
    assert isinstance(out, dict) and "hips" in out and all(isinstance(v, str) for v in out.values())


@settings(max_examples=100, deadline=None)
@given(st.integers(0, 40), st.integers(0, 60), st.integers(0, 5))
def test_fuzz_bvh_frame_counts_and_cut_rows(declared: int, frames: int, cut: int) -> None:
    text = human_bvh(frames=max(frames, 1), frames_header=declared)
    if cut:
        text = text.rstrip("\n").rsplit(" ", cut)[0] + "\n"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", BvhWarning)
        try:
            m = parse_bvh(text, "f.bvh")
        except BvhError:
            return
    assert np.isfinite(m.data).all() and m.data.shape[1] == sum(len(c) for c in m.channels)


def test_fuzz_ppclip_v2_channels(campaign, mutations, fuzz_budget, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    walk = default_clips()["walk"]
    f, j = walk.num_frames, walk.skeleton.num_joints
    clip = replace(walk, translations=walk.offsets() * 1.01, scales=np.full((f, j), 1.2))
    good = save_clip(clip, tmp_path / "good.ppclip").read_bytes()
    cases, seed = fuzz_budget(300)
    c = campaign(ClipFileError)
    assert c.run(load_clip, tmp_path / "good.ppclip") is not None  # the unmutated file reads
    path = tmp_path / "m.ppclip"
    for data in mutations(good, cases, seed):
        path.write_bytes(data)
        got = c.run(load_clip, path)
        if got is not None and got.scales is not None:
            assert np.isfinite(got.scales).all() and (got.scales > 0).all()
    c.check("ppclip v2 bytes")
