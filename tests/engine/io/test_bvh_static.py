"""A BVH rig without channels (a static skeleton: every joint ``CHANNELS 0``) is a motion like any other.

Shown to fail by mutation (docs/mutation.md, fifth round): ``rotation_columns`` without ``dtype=bool``
(an empty list becomes a float array, which cannot index the data: ``unwrapped`` raises).
"""

from __future__ import annotations

import numpy as np

from engine.io.bvh import BvhMotion


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
