"""BVH edge cases the mutation run found untested: a rig without channels, numbers only Python reads,
a header value holding a colon, a value at the limit before a NaN.

Shown to fail by mutation (docs/mutation.md, fifth round): ``rotation_columns`` without ``dtype=bool``
(an empty list becomes a float array, which cannot index the data: ``unwrapped`` raises); the line
parser's final conversion without ``dtype`` (a matrix of strings) or reshaped to ``len(rows)`` only.
Sixth round: the header split with ``rpartition(":")`` (another message), the bad-frame locator's
``< MAX_VALUE`` (names the frame holding ±1e7, not the NaN's).
"""

from __future__ import annotations

import numpy as np
import pytest

from engine.io.bvh import BvhError, BvhMotion, parse_bvh


def test_a_rig_without_channels_unwraps_to_itself() -> None:
    motion = BvhMotion(
        names=("root", "tip"),
        parents=np.array([-1, 0]),
        offsets=np.array([[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]]),
        end_sites={},
        channels=((), ()),
        frame_time=0.1,
        data=np.zeros((3, 0)),
    )
    mask = motion.rotation_columns()
    assert mask.dtype == np.bool_ and mask.shape == (0,)
    same = motion.unwrapped()
    assert same.num_frames == 3 and same.data.shape == (3, 0)
    assert same.names == motion.names and same.channels == motion.channels


def test_values_only_pythons_float_reads_go_through_the_line_parser() -> None:
    """numpy's C reader refuses ``1_0`` and non-ASCII digits; the line parser then reads every value with
    Python's ``float`` (which takes them), so the file reads with the same numbers ``float`` gives."""
    text = (
        "HIERARCHY\nROOT hips\n{\n  OFFSET 0 0 0\n  CHANNELS 3 Xposition Yposition Zrotation\n}\n"
        "MOTION\nFrames: 2\nFrame Time: 0.5\n1_0 2 3\n4 \u0665 6.5\n"
    )
    motion = parse_bvh(text, "odd.bvh")
    assert motion.data.dtype == np.float64
    np.testing.assert_array_equal(motion.data, [[10.0, 2.0, 3.0], [4.0, 5.0, 6.5]])


ONE_JOINT = "HIERARCHY\nROOT a\n{\n  OFFSET 0 0 0\n  CHANNELS 3 Xposition Yposition Zposition\n}\nMOTION\n"


@pytest.mark.parametrize("header", ["Frames: 1:2\nFrame Time: 0.1\n", "Frames: 2\nFrame Time: 0:00:01\n"])
def test_a_header_value_with_a_colon_is_a_bad_value_not_an_unknown_line(header: str) -> None:
    """The key is what comes before the *first* colon: ``Frames: 1:2`` is a ``Frames:`` line with a
    bad count (``rpartition`` would read the key ``Frames: 1`` and call the line unknown)."""
    with pytest.raises(BvhError) as err:
        parse_bvh(ONE_JOINT + header + "1 2 3\n4 5 6\n", "f.bvh")
    assert str(err.value) == "f.bvh:9: bad frame count or frame time"


@pytest.mark.parametrize("limit", ["1e7", "-1e7", "10000000"])
def test_a_value_at_the_limit_is_not_the_bad_frame(limit: str) -> None:
    """±1e7 is allowed, so a frame holding it is not the one named when a later frame holds a NaN
    (a locator testing ``< MAX_VALUE`` instead of ``<=`` would name frame 0)."""
    with pytest.raises(BvhError) as err:
        parse_bvh(ONE_JOINT + f"Frames: 3\nFrame Time: 0.1\n{limit} 2 3\n4 {limit} 6\n7 8 nan\n", "f.bvh")
    assert str(err.value) == "f.bvh: frame 2 holds a NaN, infinite or absurd value (beyond ±1e+07)"
