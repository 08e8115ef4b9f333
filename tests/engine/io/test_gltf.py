"""glTF reading of the Khronos sample models, and our writer round-tripping through the reader."""

from __future__ import annotations

import base64
import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from engine import quat
from engine.clip import Clip
from engine.fk import forward_kinematics
from engine.humanoid import humanoid_skeleton
from engine.io.bvh import read_bvh
from engine.io.gltf import GltfChannel, GltfError, read_gltf
from engine.io.gltf_clip import gltf_clip, gltf_skeleton, load_gltf_clips, sample_channel
from engine.io.gltf_write import gltf_bytes, write_gltf

# file → (skin joints, [(animation name or None, duration s, keys of the first channel)])
README = {
    "Fox.glb": (24, [("Survey", 3.417, 83), ("Walk", 0.708, 18), ("Run", 1.158, 25)]),
    "Fox.gltf": (24, [("Survey", 3.417, 83), ("Walk", 0.708, 18), ("Run", 1.158, 25)]),
    "CesiumMan.glb": (19, [(None, 2.0 - 0.042, 48)]),
    "RiggedFigure.glb": (19, [(None, 1.25, 2)]),
    "RiggedSimple.glb": (2, [(None, 2.083 - 0.042, 50)]),
    "RiggedSimple.gltf": (2, [(None, 2.083 - 0.042, 50)]),
}


def _world(asset, n: int) -> np.ndarray:  # type: ignore[no-untyped-def]
    m, chain = np.eye(4), []
    while n >= 0:
        chain.append(n)
        n = int(asset.parents[n])
    for k in reversed(chain):
        t = np.eye(4)
        t[:3, :3] = quat.to_matrix(asset.rotation[k]) * asset.scale[k]
        t[:3, 3] = asset.translation[k]
        m = m @ t
    return m


@pytest.mark.parametrize("name", sorted(README))
def test_sample_models_match_readme(mocap_dir: Path, name: str) -> None:
    joints, anims = README[name]
    asset = read_gltf(mocap_dir / name)
    assert len(asset.skins) == 1 and len(asset.skins[0].joints) == joints
    assert len(asset.animations) == len(anims)
    for anim, (anim_name, duration, keys) in zip(asset.animations, anims):
        if anim_name:
            assert anim.name == anim_name
        assert anim.duration == pytest.approx(duration, abs=2e-3)
        assert len(anim.channels[0].times) == keys
        clip = gltf_clip(asset, anim.name, fps=30)
        assert clip.duration == pytest.approx(duration, abs=1 / 30)
        wpos, _ = forward_kinematics(clip.skeleton, clip.root, clip.rotations)
        assert np.isfinite(wpos).all()


def test_gltf_and_glb_give_the_same_asset(mocap_dir: Path) -> None:
    for stem in ("Fox", "RiggedSimple"):
        a, b = read_gltf(mocap_dir / f"{stem}.glb"), read_gltf(mocap_dir / f"{stem}.gltf")
        assert a.names == b.names
        np.testing.assert_array_equal(a.translation, b.translation)
        np.testing.assert_array_equal(a.skins[0].inverse_bind, b.skins[0].inverse_bind)
        for x, y in zip(a.animations, b.animations):
            for cx, cy in zip(x.channels, y.channels):
                np.testing.assert_array_equal(cx.values, cy.values)


def test_bind_matrices_match_rest_hierarchy(mocap_dir: Path) -> None:
    # A mesh bound in the rest pose has mesh⁻¹ · joint_world · inverse_bind = I: this checks the
    # node matrix decomposition, TRS order and x,y,z,w quaternion conversion together.
    for name, mesh in (("Fox.glb", "fox"), ("CesiumMan.glb", "Cesium_Man"), ("RiggedFigure.glb", "Proxy")):
        asset = read_gltf(mocap_dir / name)
        inv_mesh = np.linalg.inv(_world(asset, asset.names.index(mesh)))
        for k, j in enumerate(asset.skins[0].joints):
            np.testing.assert_allclose(
                inv_mesh @ _world(asset, j) @ asset.skins[0].inverse_bind[k], np.eye(4), atol=2e-5
            )


def test_figures_stand_up_in_y(mocap_dir: Path) -> None:
    # CesiumMan and RiggedFigure are modelled Z-up under a Z_UP node: baked in, they stand in +Y.
    for name in ("CesiumMan.glb", "RiggedFigure.glb"):
        clip = load_gltf_clips(mocap_dir / name, fps=30)[0]
        wpos, _ = forward_kinematics(clip.skeleton, clip.root, clip.rotations)
        extent = wpos.max(axis=(0, 1)) - wpos.min(axis=(0, 1))
        assert extent[1] > 1.0 and extent[1] == extent.max()


def test_fox_static_roots_fold_into_moving_hips(mocap_dir: Path) -> None:
    asset = read_gltf(mocap_dir / "Fox.glb")
    sk = gltf_skeleton(asset)
    assert sk.names[0] == "b_Hip_01" and sk.num_joints == 22
    walk = gltf_clip(asset, "Walk", fps=24)
    assert walk.skeleton.names == sk.names
    assert np.ptp(walk.root[:, 1]) > 0.5  # the hips bob (file units are centimetres)


def test_interpolation_modes() -> None:
    times = np.array([0.0, 1.0])
    lin = GltfChannel(0, "translation", "LINEAR", times, np.array([[0.0, 0, 0], [2.0, 0, 0]]))
    np.testing.assert_allclose(sample_channel(lin, np.array([-1.0, 0.25, 2.0]))[:, 0], [0.0, 0.5, 2.0])
    step = replace(lin, interpolation="STEP")
    np.testing.assert_allclose(sample_channel(step, np.array([0.5, 1.0]))[:, 0], [0.0, 2.0])
    # cubic: in-tangent, value, out-tangent per key; zero tangents give smoothstep
    cub = GltfChannel(
        0,
        "translation",
        "CUBICSPLINE",
        times,
        np.array([[0, 0, 0], [0, 0, 0], [0, 0, 0], [0, 0, 0], [1, 0, 0], [0, 0, 0.0]]),
    )
    np.testing.assert_allclose(sample_channel(cub, np.array([0.5, 0.25]))[:, 0], [0.5, 0.15625])
    half = quat.from_axis_angle([0, 1, 0], np.pi / 2)
    rot = GltfChannel(0, "rotation", "LINEAR", times, np.stack([quat.identity(), half]))
    mid = sample_channel(rot, np.array([0.5]))[0]
    assert quat.angle_between(mid, quat.from_axis_angle([0, 1, 0], np.pi / 4)) < 1e-9


def _walk_cycle(mocap_dir: Path) -> Clip:
    clip = read_bvh(mocap_dir / "cmu_16_15_walk_daz.bvh").to_clip(skip_frames=5)
    return replace(clip, loop=True, markers={"left_down": 0.25})


@pytest.mark.parametrize("suffix", [".glb", ".gltf"])
def test_write_gltf_round_trip(mocap_dir: Path, tmp_path: Path, suffix: str) -> None:
    clip = _walk_cycle(mocap_dir)
    back = load_gltf_clips(write_gltf(tmp_path / f"walk{suffix}", clip))[0]
    assert back.skeleton.names == clip.skeleton.names
    assert back.skeleton.parents.tolist() == clip.skeleton.parents.tolist()
    np.testing.assert_allclose(back.skeleton.offsets, clip.skeleton.offsets, atol=1e-6)
    np.testing.assert_allclose(back.skeleton.tips, clip.skeleton.tips, atol=1e-6)
    assert back.num_frames == clip.num_frames and back.loop and back.markers == {"left_down": 0.25}
    assert back.fps == pytest.approx(clip.fps, rel=1e-6)
    np.testing.assert_allclose(back.root, clip.root, atol=1e-5)
    assert quat.angle_between(back.rotations, clip.rotations).max() < 1e-5


def test_written_file_is_standard_gltf(mocap_dir: Path) -> None:
    clip = _walk_cycle(mocap_dir)
    doc = json.loads(gltf_bytes(clip, binary=False))
    assert doc["asset"]["version"] == "2.0"
    blob = base64.b64decode(doc["buffers"][0]["uri"].split(",", 1)[1])
    assert len(blob) == doc["buffers"][0]["byteLength"]
    anim = doc["animations"][0]
    times = doc["accessors"][anim["samplers"][0]["input"]]
    # a loop repeats its first frame at F/fps so any viewer loops it seamlessly
    assert times["count"] == clip.num_frames + 1
    assert times["max"][0] == pytest.approx(clip.num_frames / clip.fps, rel=1e-6)
    assert len(doc["skins"][0]["joints"]) == clip.skeleton.num_joints
    glb = gltf_bytes(clip)
    assert glb[:4] == b"glTF" and int.from_bytes(glb[8:12], "little") == len(glb)


def test_puppet_clip_round_trip(tmp_path: Path) -> None:
    sk = humanoid_skeleton()
    rng = np.random.default_rng(3)
    rots = quat.normalize(quat.identity(8, sk.num_joints) + 0.2 * rng.normal(size=(8, sk.num_joints, 4)))
    clip = Clip("wiggle", sk, 30.0, rng.normal(size=(8, 3)), rots)
    back = load_gltf_clips(write_gltf(tmp_path / "w.glb", clip))[0]
    np.testing.assert_allclose(back.skeleton.radii, sk.radii, atol=1e-9)
    assert not back.loop and back.num_frames == 8
    assert quat.angle_between(back.rotations, clip.rotations).max() < 1e-5


def test_bad_files_give_clear_errors(mocap_dir: Path, tmp_path: Path) -> None:
    data = (mocap_dir / "RiggedSimple.glb").read_bytes()
    cut = tmp_path / "cut.glb"
    cut.write_bytes(data[: len(data) // 2])
    with pytest.raises(GltfError, match="cut.glb: truncated"):
        read_gltf(cut)
    lonely = tmp_path / "lonely.gltf"
    lonely.write_text((mocap_dir / "RiggedSimple.gltf").read_text())
    with pytest.raises(GltfError, match="RiggedSimple.bin"):
        read_gltf(lonely)
    junk = tmp_path / "junk.gltf"
    junk.write_text("{ not json")
    with pytest.raises(GltfError, match="junk.gltf"):
        read_gltf(junk)
    with pytest.raises(GltfError, match="no animation 'Dance'"):
        gltf_clip(read_gltf(mocap_dir / "Fox.glb"), "Dance")
    with pytest.raises(ValueError, match=".fbx"):
        write_gltf(tmp_path / "x.fbx", _walk_cycle(mocap_dir))


def _doc(tmp_path: Path) -> tuple[Path, dict]:  # type: ignore[type-arg]
    sk = humanoid_skeleton()
    clip = Clip("still", sk, 30.0, np.zeros((4, 3)), quat.identity(4, sk.num_joints))
    path = write_gltf(tmp_path / "c.gltf", clip)
    return path, json.loads(path.read_text())


@pytest.mark.parametrize(
    "edit,says",
    [
        (lambda d: d["nodes"][0].update(children=[0]), "cycle"),  # looped forever in gltf_clip
        (lambda d: d["nodes"][1].update(children=[*d["nodes"][1].get("children", []), 0]), "cycle|shared"),
        (lambda d: d["accessors"][0].update(count=10**10), "count"),
        (lambda d: d["accessors"][0].update(count="many"), "count"),
        (lambda d: d["nodes"][0].update(translation=[float("nan"), 0, 0]), "finite"),
        (lambda d: d.update(nodes="abc"), "malformed"),
        (lambda d: d["animations"][0].update(channels=[{"sampler": 0, "target": "node"}]), "malformed"),
        (lambda d: d["animations"][0].setdefault("extras", {}).update(fps=1e12), "fps"),
        (lambda d: d["animations"][0].setdefault("extras", {}).update(fps=float("nan")), "fps"),
    ],
)
def test_hostile_documents_are_gltf_errors(tmp_path: Path, edit, says) -> None:  # type: ignore[no-untyped-def]
    path, doc = _doc(tmp_path)
    edit(doc)
    path.write_text(json.dumps(doc))
    with pytest.raises(GltfError, match=says):
        load_gltf_clips(path)


def test_key_times_far_apart_do_not_allocate_frames(tmp_path: Path) -> None:
    path, doc = _doc(tmp_path)
    times = np.array([0.0, 9e4], dtype="<f4").tobytes()
    doc["buffers"].append(
        {"byteLength": 8, "uri": "data:application/octet-stream;base64," + base64.b64encode(times).decode()}
    )
    doc["bufferViews"].append({"buffer": len(doc["buffers"]) - 1, "byteLength": 8})
    doc["accessors"].append(
        {"bufferView": len(doc["bufferViews"]) - 1, "componentType": 5126, "count": 2, "type": "SCALAR"}
    )
    sampler = doc["animations"][0]["samplers"][0]
    n_out = doc["accessors"][sampler["output"]]["count"]
    doc["accessors"][sampler["output"]]["count"] = 2 if n_out >= 2 else n_out
    sampler["input"] = len(doc["accessors"]) - 1
    path.write_text(json.dumps(doc))
    with pytest.raises(GltfError, match="node-frames"):
        load_gltf_clips(path)


def test_a_signalling_nan_in_a_buffer_is_a_gltf_error(tmp_path: Path) -> None:
    path, doc = _doc(tmp_path)
    snan = b"\x01\x00\xa0\x7f" * 2  # float32 signalling NaNs: widening them raised a RuntimeWarning
    doc["buffers"].append(
        {"byteLength": 8, "uri": "data:application/octet-stream;base64," + base64.b64encode(snan).decode()}
    )
    doc["bufferViews"].append({"buffer": len(doc["buffers"]) - 1, "byteLength": 8})
    doc["accessors"].append(
        {"bufferView": len(doc["bufferViews"]) - 1, "componentType": 5126, "count": 2, "type": "SCALAR"}
    )
    doc["animations"][0]["samplers"][0]["input"] = len(doc["accessors"]) - 1
    path.write_text(json.dumps(doc))
    with pytest.raises(GltfError, match="NaN"):
        read_gltf(path)
