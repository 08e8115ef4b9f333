"""A glTF node's *rest* scale is baked into the bone offsets below it (not a scale channel).

Shown to fail when broken: the rest scale ignored (``own = 1.0`` in ``gltf_clip._build``), applied
to the node's own offset instead of its children's (``trans[:, 1:] *= wscale[1:]``), or not carried
down to grandchildren (``wscale[k] = own``).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from engine import quat
from engine.clip import Clip
from engine.humanoid import humanoid_skeleton
from engine.io.gltf_clip import load_gltf_clips
from engine.io.gltf_write import write_gltf


def test_a_rest_scale_on_an_inner_joint_lengthens_every_bone_below_it(tmp_path: Path) -> None:
    sk = humanoid_skeleton()
    clip = Clip("still", sk, 30.0, np.tile(sk.offsets[0], (4, 1)), quat.identity(4, sk.num_joints))
    path = write_gltf(tmp_path / "c.gltf", clip)
    doc = json.loads(path.read_text())
    node = next(n for n in doc["nodes"] if n.get("name") == "l_upper_arm")
    node["scale"] = [2.0, 2.0, 2.0]
    path.write_text(json.dumps(doc))

    back = load_gltf_clips(path)[0]
    assert back.scales is None  # a rest scale is not an animated scale channel
    bs = back.skeleton
    assert list(bs.names) == list(sk.names)
    below = {sk.index("l_lower_arm"), sk.index("l_hand")}
    for j in range(sk.num_joints):
        factor = 2.0 if j in below else 1.0
        np.testing.assert_allclose(bs.offsets[j], factor * sk.offsets[j], atol=1e-6, err_msg=sk.names[j])
        np.testing.assert_allclose(
            bs.tips[j],
            (2.0 if j in below | {sk.index("l_upper_arm")} else 1.0) * sk.tips[j],
            atol=1e-6,
            err_msg=sk.names[j],
        )
