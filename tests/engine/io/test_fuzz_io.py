"""Fuzzing the asset loaders: ``.ppclip``, BVH and glTF, by byte mutation of real files.

Allowed outcomes: a clip / motion / asset whose numbers are all finite, or the format's own
error (``ClipFileError``, ``BvhError``, ``GltfError``). Never another exception, a hang or a
large allocation (``Campaign`` in ``tests/conftest.py``).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from engine import quat
from engine.clip import Clip
from engine.clipfile import ClipFileError, _digest, load_clip, save_clip
from engine.humanoid import humanoid_skeleton
from engine.io.bvh import BvhError, parse_bvh
from engine.io.gltf import GltfError, read_gltf
from engine.io.gltf_clip import load_gltf_clips
from engine.io.gltf_mesh import read_skinned_meshes
from engine.io.gltf_write import write_gltf

pytestmark = pytest.mark.fuzz


def _finite(*arrays: np.ndarray) -> None:
    for a in arrays:
        assert np.isfinite(np.asarray(a, dtype=np.float64)).all()


def _check_clip(clip: Clip) -> None:
    _finite(clip.root, clip.rotations, clip.skeleton.offsets, clip.skeleton.tips, clip.skeleton.radii)
    assert 0 < clip.fps <= 1000 and (clip.skeleton.radii >= 0).all()


def _small_clip() -> Clip:
    sk = humanoid_skeleton()
    rng = np.random.default_rng(1)
    rots = quat.normalize(quat.identity(6, sk.num_joints) + 0.1 * rng.normal(size=(6, sk.num_joints, 4)))
    return Clip("fuzz", sk, 30.0, rng.normal(size=(6, 3)), rots, loop=True, markers={"step": 0.1})


def test_fuzz_ppclip_bytes(campaign, mutations, fuzz_budget, tmp_path):
    good = save_clip(_small_clip(), tmp_path / "good.ppclip").read_bytes()
    cases, seed = fuzz_budget(1500)
    c = campaign(ClipFileError)
    path = tmp_path / "m.ppclip"
    for data in mutations(good, cases, seed):
        path.write_bytes(data)
        clip = c.run(load_clip, path)
        if clip is not None:
            _check_clip(clip)
    c.check("ppclip bytes")


json_leaf = st.one_of(
    st.none(), st.booleans(), st.integers(-(2**70), 2**70), st.floats(allow_nan=True), st.text(max_size=6)
)


@given(
    st.sampled_from(["fps", "name", "loop", "markers", "joints", "version", "format"]),
    st.recursive(
        json_leaf,
        lambda inner: st.one_of(st.lists(inner, max_size=3), st.dictionaries(st.text(max_size=4), inner, max_size=3)),
        max_leaves=8,
    ),
)
def test_fuzz_ppclip_headers_even_correctly_signed(tmp_path_factory, key, value):
    path = save_clip(_small_clip(), tmp_path_factory.mktemp("c") / "c.ppclip")
    with np.load(path) as data:
        arrays = {k: data[k] for k in data.files}
    header = json.loads(arrays.pop("header").tobytes())
    header[key] = value
    header["sha256"] = _digest(arrays)
    with open(path, "wb") as f:
        np.savez(f, header=np.frombuffer(json.dumps(header).encode(), dtype=np.uint8), **arrays)
    try:
        clip = load_clip(path)
    except ClipFileError:
        return
    _check_clip(clip)


def _bvh_head(mocap_dir: Path, frames: int = 12) -> bytes:
    text = (mocap_dir / "cmu_16_15_walk_daz.bvh").read_text()
    head, _, motion = text.partition("MOTION")
    lines = motion.strip().splitlines()
    return (
        head + "MOTION\nFrames: " + str(frames) + "\n" + lines[1] + "\n" + "\n".join(lines[2 : 2 + frames]) + "\n"
    ).encode()


def _check_motion(text: bytes) -> None:
    m = parse_bvh(text.decode("latin-1"), "fuzz.bvh")
    _finite(m.offsets, m.data, *m.end_sites.values())
    assert 0 < m.frame_time <= 10


@pytest.mark.slow  # 1200 parses under tracemalloc: ~15 s of CPU
def test_fuzz_bvh_bytes(campaign, mutations, fuzz_budget, mocap_dir):
    cases, seed = fuzz_budget(1200)
    c = campaign(BvhError)
    for data in mutations(_bvh_head(mocap_dir), cases, seed):
        c.run(_check_motion, data)
    c.check("bvh text")


def _check_gltf(path: Path) -> None:
    asset = read_gltf(path)
    _finite(asset.translation, asset.rotation, asset.scale)
    for anim in asset.animations:
        for ch in anim.channels:
            _finite(ch.times, ch.values)
    if asset.skins and asset.animations:
        for clip in load_gltf_clips(path):
            _finite(clip.root, clip.rotations)


@pytest.mark.parametrize("name", ["RiggedSimple.glb", "RiggedSimple.gltf"])
def test_fuzz_gltf_bytes(campaign, mutations, fuzz_budget, mocap_dir, tmp_path, name):
    good = (mocap_dir / name).read_bytes()
    (tmp_path / "RiggedSimple.bin").write_bytes((mocap_dir / "RiggedSimple.bin").read_bytes())
    cases, seed = fuzz_budget(1500)
    c = campaign((GltfError,))
    path = tmp_path / ("m" + Path(name).suffix)
    for data in mutations(good, cases, seed):
        path.write_bytes(data)
        c.run(_check_gltf, path)
    c.check(f"gltf {name}")


def test_fuzz_our_own_gltf_as_json(campaign, mutations, fuzz_budget, tmp_path):
    good = write_gltf(tmp_path / "c.gltf", _small_clip()).read_bytes()
    cases, seed = fuzz_budget(1500)
    c = campaign((GltfError,))
    path = tmp_path / "m.gltf"
    for data in mutations(good, cases, seed):
        path.write_bytes(data)
        c.run(_check_gltf, path)
    c.check("gltf (our writer's)")


def _check_skinned(path: Path) -> None:
    """Whatever reads must be drawable: finite, weights summing to one, every index in range."""
    meshes = read_skinned_meshes(path)
    joints = len(read_gltf(path).skins[meshes.skin].joints)
    for prim in meshes.primitives:
        _finite(prim.positions, prim.normals, prim.uv, prim.weights)
        assert np.allclose(prim.weights.sum(axis=1), 1.0, atol=1e-5)
        assert int(prim.joints.max()) < joints and int(prim.indices.max()) < len(prim.positions)


def test_fuzz_skinned_mesh_bytes(campaign, mutations, fuzz_budget, mocap_dir, tmp_path):
    """The skinned-mesh reader (characters drawn in the renderer) over a real skinned GLB."""
    good = (mocap_dir / "RiggedFigure.glb").read_bytes()
    cases, seed = fuzz_budget(600)
    c = campaign((GltfError,))
    path = tmp_path / "m.glb"
    for data in mutations(good, cases, seed):
        path.write_bytes(data)
        c.run(_check_skinned, path)
    c.check("skinned gltf mesh")
