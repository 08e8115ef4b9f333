"""BVH edge cases the mutation run found untested: a rig without channels, numbers only Python reads.

Shown to fail by mutation (docs/mutation.md, fifth round): ``rotation_columns`` without ``dtype=bool``
(an empty list becomes a float array, which cannot index the data: ``unwrapped`` raises); the line
parser's final conversion without ``dtype`` (a matrix of strings) or reshaped to ``len(rows)`` only.
"""

from __future__ import annotations

import numpy as np

from engine.io.bvh import BvhMotion, parse_bvh


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
