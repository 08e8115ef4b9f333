"""A skin driven by the engine's FK of a clip made from the same file lands where the file's own
skinning puts it (up to the one similarity the importer applied: unit, up axis, placement)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from engine.fk import forward_kinematics
from engine.io.gltf import read_gltf
from engine.io.gltf_clip import load_gltf_clips
from engine.io.gltf_mesh import read_skinned_meshes
from engine.skeleton import Skeleton
from engine.skinning import SkinBinding, blend_skin, fit_similarity, node_world_matrices, skin_matrices


# CesiumMan's engine clip differs from its file by up to ~3 mm (its skeleton comes out 0.03 %
# longer); Fox (75 units tall) and RiggedFigure match to rounding.
@pytest.mark.parametrize("name, tolerance", [("CesiumMan.glb", 5e-3), ("Fox.glb", 1e-6), ("RiggedFigure.glb", 1e-5)])
def test_engine_fk_drives_the_skin_as_the_file_does(mocap_dir: Path, name: str, tolerance: float) -> None:
    path = mocap_dir / name
    asset, meshes = read_gltf(path), read_skinned_meshes(path)
    clip, anim = load_gltf_clips(path)[0], asset.animations[0]
    binding = SkinBinding.bind(asset, meshes, clip.skeleton)
    prim = meshes.primitives[0]
    for t in (0.0, 0.3 * clip.duration, 0.7 * clip.duration):
        pose = clip.sample(t)
        pos, rot = forward_kinematics(clip.skeleton, pose.root, pose.rotations, pose.offsets, pose.scales)
        ours = blend_skin(prim.positions, prim.joints, prim.weights, binding.matrices(pos, rot))
        file = blend_skin(
            prim.positions,
            prim.joints,
            prim.weights,
            skin_matrices(asset, node_world_matrices(asset, anim, anim.start + t)),
        )
        c = fit_similarity(file, ours)
        height = float(np.ptp(ours[:, 1]))
        assert np.abs((c[:3, :3] @ file.T).T + c[:3, 3] - ours).max() < tolerance * max(height / 1.5, 1.0)


def test_a_skeleton_of_other_names_is_refused_naming_the_missing_joints(mocap_dir: Path) -> None:
    path = mocap_dir / "CesiumMan.glb"
    asset, meshes = read_gltf(path), read_skinned_meshes(path)
    sk = load_gltf_clips(path)[0].skeleton
    renamed = Skeleton(tuple(f"other{k}" for k in range(sk.num_joints)), sk.parents, sk.offsets)
    with pytest.raises(ValueError, match="shares too few joints.*missing: Skeleton"):
        SkinBinding.bind(asset, meshes, renamed)


def test_a_skeleton_in_another_unit_carries_the_skin_in_that_unit(mocap_dir: Path) -> None:
    """Fox is 75 file units tall; the importers bring it to metres by scaling the bone offsets."""
    path = mocap_dir / "Fox.glb"
    asset, meshes = read_gltf(path), read_skinned_meshes(path)
    clip = load_gltf_clips(path)[0]
    metres = Skeleton(clip.skeleton.names, clip.skeleton.parents, clip.skeleton.offsets * 0.01)
    binding = SkinBinding.bind(asset, meshes, metres)
    pose = clip.sample(0.5)
    offsets = None if pose.offsets is None else pose.offsets * 0.01
    pos, rot = forward_kinematics(metres, pose.root * 0.01, pose.rotations, offsets, pose.scales)
    prim = meshes.primitives[0]
    ours = blend_skin(prim.positions, prim.joints, prim.weights, binding.matrices(pos, rot))
    anim = asset.animations[0]
    file = blend_skin(
        prim.positions,
        prim.joints,
        prim.weights,
        skin_matrices(asset, node_world_matrices(asset, anim, anim.start + 0.5)),
    )
    assert np.abs(ours - 0.01 * file).max() < 1e-6
