"""Reading skinned meshes: real characters load with their textures; every broken rule is one
GltfError naming the file, never a traceback or an out-of-range index reaching the GPU."""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from engine.io.gltf import GltfError, read_gltf
from engine.io.gltf_mesh import read_skinned_meshes
from engine.io.gltf_write import container_bytes
from engine.skinning import bind_from_engine, blend_skin, node_world_matrices, rigid_matrices, skin_matrices


def _two_bone_doc() -> tuple[dict[str, Any], bytes]:
    """A 2-joint skin with one triangle strip of 4 vertices (weights split between the bones)."""
    pos = np.array([[0, 0, 0], [0.1, 0, 0], [0, 1, 0], [0.1, 1, 0]], dtype=np.float32)
    joints = np.array([[0, 1, 0, 0]] * 4, dtype=np.uint16)
    weights = np.array([[1, 0, 0, 0], [1, 0, 0, 0], [0.25, 0.75, 0, 0], [0.5, 0.5, 0, 0]], dtype=np.float32)
    idx = np.array([0, 1, 2, 2, 1, 3], dtype=np.uint16)
    ibm = np.stack([np.eye(4), np.eye(4)]).astype(np.float32)
    ibm[1, 1, 3] = -0.5  # bone 1 starts at y = 0.5 (inverse: -0.5), stored column-major below
    parts = [pos.tobytes(), joints.tobytes(), weights.tobytes(), idx.tobytes(), ibm.transpose(0, 2, 1).tobytes()]
    offsets = np.cumsum([0] + [len(p) for p in parts])
    blob = b"".join(parts)
    views = [{"buffer": 0, "byteOffset": int(o), "byteLength": len(p)} for o, p in zip(offsets, parts)]
    doc = {
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": len(blob)}],
        "bufferViews": views,
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3"},
            {"bufferView": 1, "componentType": 5123, "count": 4, "type": "VEC4"},
            {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC4"},
            {"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"},
            {"bufferView": 4, "componentType": 5126, "count": 2, "type": "MAT4"},
        ],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "JOINTS_0": 1, "WEIGHTS_0": 2}, "indices": 3}]}],
        "skins": [{"joints": [1, 2], "inverseBindMatrices": 4}],
        "nodes": [
            {"mesh": 0, "skin": 0},
            {"children": [2]},
            {"translation": [0, 0.5, 0], "rotation": [0, 0, 0.3826834, 0.9238795]},
        ],
        "scenes": [{"nodes": [0, 1]}],
    }
    return doc, blob


def _write(tmp_path: Path, doc: dict[str, Any], blob: bytes, name: str = "c.glb") -> Path:
    path = tmp_path / name
    path.write_bytes(container_bytes(copy.deepcopy(doc), blob, binary=True))
    return path


def test_a_generated_skin_reads_and_skins_by_hand(tmp_path: Path) -> None:
    doc, blob = _two_bone_doc()
    path = _write(tmp_path, doc, blob)
    meshes = read_skinned_meshes(path)
    (prim,) = meshes.primitives
    assert prim.indices.tolist() == [0, 1, 2, 2, 1, 3] and prim.texture is None
    assert np.allclose(prim.normals, [0, 0, 1], atol=1e-6)  # no NORMAL in the file: made from the faces
    asset = read_gltf(path)
    out = blend_skin(prim.positions, prim.joints, prim.weights, skin_matrices(asset, node_world_matrices(asset)))
    # Bone 1 is turned 45° about z at y = 0.5: vertex 2 (0, 1) is a quarter on bone 0, three quarters turned.
    c = np.cos(np.pi / 4)
    turned = np.array([0.5 * -c * 1.0, 0.5 + 0.5 * c, 0.0])  # (0, 0.5) above the pivot, turned by 45°
    assert np.allclose(out[2], 0.25 * np.array([0, 1, 0]) + 0.75 * turned, atol=1e-6)
    assert np.allclose(out[:2], prim.positions[:2], atol=1e-7)  # fully on the resting bone


@pytest.mark.parametrize("name, unit", [("CesiumMan.glb", 100.0), ("two bones", 1.0)])
def test_engine_poses_carry_onto_the_skin_whatever_the_unit_and_up(
    tmp_path: Path, mocap_dir: Path, name: str, unit: float
) -> None:
    if name == "two bones":  # joints in a line: the scale cannot be seen, the frame carries the move
        doc, blob = _two_bone_doc()
        path = _write(tmp_path, doc, blob)
    else:
        path = mocap_dir / name
    asset = read_gltf(path)
    prim = read_skinned_meshes(path).primitives[0]
    anim = asset.animations[0] if asset.animations else None
    joints = list(asset.skins[0].joints)
    # The engine holds the figure in another unit, turned Z-up and moved: any similarity C.
    c = np.eye(4)
    c[:3, :3] = unit * np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]])
    c[:3, 3] = [3.0, -2.0, 7.0]

    def engine_pose(world: np.ndarray) -> np.ndarray:
        placed = c @ world[joints]
        return rigid_matrices(placed[:, :3, 3], _rotations(placed))

    bind = bind_from_engine(asset, engine_pose(node_world_matrices(asset)), joints)
    for time in (0.0, 0.4):  # at rest and in a pose of the animation
        world = node_world_matrices(asset, anim, time)
        skinned = blend_skin(prim.positions, prim.joints, prim.weights, engine_pose(world) @ bind)
        by_file = blend_skin(prim.positions, prim.joints, prim.weights, skin_matrices(asset, world))
        assert np.abs(skinned - ((c[:3, :3] @ by_file.T).T + c[:3, 3])).max() < 1e-6 * unit


def _rotations(m: np.ndarray) -> np.ndarray:
    from engine import quat

    r = m[:, :3, :3] / np.linalg.norm(m[:, :3, :3], axis=1, keepdims=True)
    return quat.from_matrix(r)


def test_real_characters_load_with_their_textures(mocap_dir: Path) -> None:
    cesium = read_skinned_meshes(mocap_dir / "CesiumMan.glb")
    (prim,) = cesium.primitives
    assert prim.texture is not None and prim.texture.shape[2] == 4 and prim.texture.std() > 10
    assert np.allclose(prim.weights.sum(axis=1), 1.0, atol=1e-6)
    assert prim.joints.max() < len(read_gltf(mocap_dir / "CesiumMan.glb").skins[0].joints)
    assert prim.uv.min() >= 0.0 and prim.uv.max() <= 1.0


@pytest.mark.parametrize(
    "break_it, message",
    [
        (lambda d: d["skins"][0].update(joints=[1]), "JOINTS_0 names joints outside"),
        (lambda d: d["meshes"][0]["primitives"][0]["attributes"].pop("WEIGHTS_0"), "no JOINTS_0/WEIGHTS_0"),
        (lambda d: d["accessors"][3].update(count=5), "not whole triangles"),
        (lambda d: d["nodes"][0].pop("skin"), "no mesh is skinned"),
        (lambda d: d.pop("skins"), "has no skin"),
        (lambda d: d["meshes"][0]["primitives"][0].update(material=4), "material 4 is not"),
        (lambda d: d["accessors"][0].update(count=1 << 30), "count"),
        (lambda d: d["meshes"][0]["primitives"][0]["attributes"].update(POSITION="x"), "malformed|missing"),
    ],
)
def test_broken_rules_are_one_line_errors(tmp_path: Path, break_it, message: str) -> None:
    doc, blob = _two_bone_doc()
    break_it(doc)
    with pytest.raises(GltfError, match=message) as err:
        read_skinned_meshes(_write(tmp_path, doc, blob))
    assert "\n" not in str(err.value) and "c.glb" in str(err.value)


def test_zero_weights_are_refused(tmp_path: Path) -> None:
    doc, blob = _two_bone_doc()
    raw = bytearray(blob)
    start = doc["bufferViews"][2]["byteOffset"]
    raw[start : start + 16] = np.zeros(4, dtype=np.float32).tobytes()
    with pytest.raises(GltfError, match="1 vertices have no skin weight"):
        read_skinned_meshes(_write(tmp_path, doc, bytes(raw)))
