"""glTF CUBICSPLINE out and in for keyframed clips: keys and tangents survive; other readers play it the same."""

from __future__ import annotations

import numpy as np
import pytest

from engine.clips import default_clips
from engine.fk import forward_kinematics
from engine.io.gltf import GltfError
from engine.io.gltf_clip import load_gltf_clips
from engine.io.gltf_cubic import read_gltf_cubic, write_gltf_cubic
from engine.io.gltf_write import write_gltf
from engine.keyframes import keyframe_clip


@pytest.mark.parametrize("suffix", [".glb", ".gltf"])
def test_keys_and_tangents_round_trip(tmp_path, suffix):
    kc = keyframe_clip(default_clips()["walk"], every=6)
    path = write_gltf_cubic(tmp_path / f"walk{suffix}", kc)
    back = read_gltf_cubic(path)
    c, b = kc.curves, back.curves
    assert back.loop and back.curves.times.size == c.times.size
    tol = 1e-6  # glTF accessors are float32
    assert np.allclose(b.times, c.times, atol=tol) and np.allclose(b.values, c.values, atol=tol)
    assert np.allclose(b.out_y[:-1], c.out_y[:-1], atol=tol) and np.allclose(b.in_y[1:], c.in_y[1:], atol=tol)
    p0, _ = forward_kinematics(kc.skeleton, kc.bake().root, kc.bake().rotations)
    p1, _ = forward_kinematics(back.skeleton, back.bake().root, back.bake().rotations)
    assert np.abs(p1 - p0).max() < 1e-5
    # Any glTF player (here the engine's own sampling reader) shows the same motion.
    played = load_gltf_clips(path)[0]
    p2, _ = forward_kinematics(played.skeleton, played.root, played.rotations)
    assert played.num_frames == kc.num_frames and np.abs(p2 - p0).max() < 2e-3


def test_a_sampled_file_is_refused_in_one_line(tmp_path):
    path = write_gltf(tmp_path / "linear.glb", default_clips()["walk"])
    with pytest.raises(GltfError, match="not CUBICSPLINE"):
        read_gltf_cubic(path)
