"""A rigged glTF humanoid as a puppet skeleton: the puppet's roles, the character's sizes, its skin following.

Each test says how it was seen to fail."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from engine import quat
from engine.character.load import read_character
from engine.fk import forward_kinematics
from engine.humanoid import JOINTS, humanoid_skeleton
from engine.io.gltf import read_gltf
from engine.skinning import blend_skin, node_world_matrices, skin_matrices


@pytest.fixture(scope="module")
def cesium(request: pytest.FixtureRequest):  # type: ignore[no-untyped-def]
    from tests.conftest import data_dir

    d = data_dir()
    if d is None:
        pytest.skip("real mocap data not found")
    path = d / "mocap" / "CesiumMan.glb"
    return path, read_character(path)[0]


def _skinned(binding, pos: np.ndarray, rot: np.ndarray) -> np.ndarray:  # type: ignore[no-untyped-def]
    m = binding.matrices(pos, rot)
    return np.concatenate([blend_skin(p.positions, p.joints, p.weights, m) for p in binding.meshes.primitives])


def test_the_rest_pose_puts_the_roles_where_the_file_has_its_joints(cesium) -> None:  # type: ignore[no-untyped-def]
    """Broken by taking every offset from the file (limbs then no longer hang): the limb check fails."""
    path, ch = cesium
    rig, sk = ch.rig, ch.rig.skeleton
    assert sk.names == JOINTS
    asset = read_gltf(path)
    world = node_world_matrices(asset)
    nodes = {asset.names[n]: n for n in asset.skins[0].joints}
    want = np.array([rig.to_engine[:3, :3] @ world[nodes[ch.roles[r]], :3, 3] + rig.to_engine[:3, 3] for r in JOINTS])
    pos, _ = forward_kinematics(sk, sk.offsets[0], rig.rest_local)
    assert np.abs(pos - want).max() < 1e-6
    base = humanoid_skeleton()
    for limb in ("l_lower_arm", "r_hand", "l_lower_leg", "r_foot"):
        j = sk.index(limb)
        cos = sk.offsets[j] @ base.offsets[j] / np.linalg.norm(sk.offsets[j]) / np.linalg.norm(base.offsets[j])
        assert cos > 1 - 1e-9, limb  # hanging like the puppet's, whatever the file's A-pose
    assert ch.roles["l_upper_leg"] == "leg_joint_L_1" and pos[sk.index("l_foot"), 0] > 0  # left is +X, as the puppet's


def test_at_rest_the_skin_lands_where_the_files_own_skinning_puts_it(cesium) -> None:  # type: ignore[no-untyped-def]
    """Broken by binding without ``to_engine``: off by the hips' placement over the origin (5 mm)."""
    path, ch = cesium
    asset = read_gltf(path)
    mats = skin_matrices(asset, node_world_matrices(asset))
    own = np.concatenate([blend_skin(p.positions, p.joints, p.weights, mats) for p in ch.binding.meshes.primitives])
    own = own @ ch.rig.to_engine[:3, :3].T + ch.rig.to_engine[:3, 3]
    sk = ch.rig.skeleton
    pos, rot = forward_kinematics(sk, sk.offsets[0], ch.rig.rest_local)
    got = _skinned(ch.binding, pos, rot)
    assert np.abs(got - own).max() < 1e-9
    assert abs(got[:, 1].min()) < 1e-9  # the soles on the floor


def test_a_bent_knee_carries_the_foot_rigidly_with_the_puppets_shin(cesium) -> None:  # type: ignore[no-untyped-def]
    """Vertices weighted wholly to the foot keep their place in the engine foot's frame.

    Broken by driving every skin joint from the hips: no vertex follows the foot any more (the count fails)."""
    _, ch = cesium
    sk = ch.rig.skeleton
    local = np.array(ch.rig.rest_local)
    knee, foot = sk.index("l_lower_leg"), sk.index("l_foot")
    local[knee] = quat.mul(local[knee], quat.from_axis_angle(np.array([1.0, 0.0, 0.0]), np.radians(70.0)))
    pos0, rot0 = forward_kinematics(sk, sk.offsets[0], ch.rig.rest_local)
    pos1, rot1 = forward_kinematics(sk, sk.offsets[0], local)
    rest, bent = _skinned(ch.binding, pos0, rot0), _skinned(ch.binding, pos1, rot1)
    drivers = ch.binding.drivers
    owned = np.concatenate(
        [(p.weights * (drivers[p.joints] != foot)).sum(axis=1) < 1e-6 for p in ch.binding.meshes.primitives]
    )
    assert owned.sum() > 50
    in_foot0 = quat.rotate(quat.conjugate(rot0[foot]), rest[owned] - pos0[foot])
    in_foot1 = quat.rotate(quat.conjugate(rot1[foot]), bent[owned] - pos1[foot])
    assert np.abs(in_foot0 - in_foot1).max() < 1e-6  # float32 weights sum to one within ~1e-7
    assert np.linalg.norm(bent[owned] - rest[owned], axis=1).min() > 0.05  # and the foot did move


def test_the_capsules_are_as_thick_as_the_mesh_and_the_mass_follows(cesium) -> None:  # type: ignore[no-untyped-def]
    """A 1.5 m character is lighter than the 1.75 m mannequin; broken by the default 70 kg: fails."""
    from engine.character.puppet import MANNEQUIN_MASS, character_profile

    _, ch = cesium
    sk = ch.rig.skeleton
    profile = character_profile(sk)
    assert 30.0 < profile.masses.sum() < 0.8 * MANNEQUIN_MASS
    assert sk.radii[sk.index("head")] > sk.radii[sk.index("neck")]  # measured from the mesh, not one figure


def test_a_file_facing_minus_z_is_turned_round(cesium, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    """The rig is built from positions: mirrored front to back (x and z negated), the character faces -Z
    in the file and must still face +Z with its left at +X. Broken by dropping the turn: left lands at -X."""
    from engine.character.rig import build_rig

    _, ch = cesium
    p = ch.rig.rest_positions
    turned = {r: p[i] * np.array([-1.0, 1.0, -1.0]) for i, r in enumerate(JOINTS)}
    rig = build_rig(turned, 0.0)
    assert np.abs(rig.rest_positions - p).max() < 1e-9
