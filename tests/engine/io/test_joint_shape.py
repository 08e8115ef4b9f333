"""Roles by shape: rigs whose names follow no family still map onto the puppet, whichever way they
stand; shapes that are not standing humanoids are refused in one line."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from engine import quat
from engine.fk import forward_kinematics
from engine.humanoid import humanoid_skeleton
from engine.io.gltf import read_gltf
from engine.io.gltf_clip import load_gltf_clips
from engine.io.joint_shape import guess_clip_joint_map, guess_roles_by_shape
from engine.io.motion_file import to_puppet
from engine.skinning import node_world_matrices

CESIUM = {
    "hips": "Skeleton_torso_joint_1",
    "spine": "Skeleton_torso_joint_2",
    "chest": "torso_joint_3",
    "neck": "Skeleton_neck_joint_1",
    "head": "Skeleton_neck_joint_2",
    "l_upper_leg": "leg_joint_L_1",
    "l_lower_leg": "leg_joint_L_2",
    "l_foot": "leg_joint_L_3",
    "r_upper_leg": "leg_joint_R_1",
    "r_lower_leg": "leg_joint_R_2",
    "r_foot": "leg_joint_R_3",
    "l_upper_arm": "Skeleton_arm_joint_L__4_",
    "l_lower_arm": "Skeleton_arm_joint_L__3_",
    "l_hand": "Skeleton_arm_joint_L__2_",
    "r_upper_arm": "Skeleton_arm_joint_R",
    "r_lower_arm": "Skeleton_arm_joint_R__2_",
    "r_hand": "Skeleton_arm_joint_R__3_",
}


def _skin_pose(path: Path) -> tuple[list[str], np.ndarray, np.ndarray]:
    asset = read_gltf(path)
    world = node_world_matrices(asset)
    joints = list(asset.skins[0].joints)
    parents = np.array([joints.index(int(asset.parents[j])) if int(asset.parents[j]) in joints else -1 for j in joints])
    return [asset.names[j] for j in joints], parents, world[joints, :3, 3]


def _turned(points: np.ndarray, axis: tuple[float, float, float], angle: float) -> np.ndarray:
    return quat.rotate(quat.from_axis_angle(np.array(axis), angle), points)


@pytest.mark.parametrize("turn", [None, ((0, 1, 0), np.pi / 2), ((0, 1, 0), np.pi), ((1, 0, 0), np.pi / 2)])
def test_cesium_man_maps_whichever_way_it_stands(mocap_dir: Path, turn) -> None:
    names, parents, pos = _skin_pose(mocap_dir / "CesiumMan.glb")
    if turn is not None:  # facing elsewhere, or lying in a Z-up file
        pos = _turned(pos, *turn)
    assert guess_roles_by_shape(names, parents, pos) == CESIUM


def test_the_mannequin_under_other_names_maps_to_its_own_roles() -> None:
    sk = humanoid_skeleton()
    pos, _ = forward_kinematics(sk, sk.offsets[0], quat.identity(sk.num_joints))
    hidden = [f"j{k:02d}" for k in range(sk.num_joints)]
    roles = guess_roles_by_shape(hidden, sk.parents, pos)
    assert {role: sk.names[hidden.index(j)] for role, j in roles.items()} == {n: n for n in sk.names}


def test_a_rig_of_known_names_keeps_its_family_and_an_unknown_one_goes_by_shape(mocap_dir: Path) -> None:
    sk = humanoid_skeleton()
    from engine.clips import default_clips

    assert guess_clip_joint_map(default_clips()["walk"])[0] == "puppetphone"
    family, mapping, _ = guess_clip_joint_map(load_gltf_clips(mocap_dir / "CesiumMan.glb")[0])
    assert family == "shape" and mapping == CESIUM
    puppet, used = to_puppet(load_gltf_clips(mocap_dir / "CesiumMan.glb")[0])
    assert used == "shape" and puppet.skeleton.names == sk.names


@pytest.mark.parametrize("name, message", [("Fox.glb", "left and right|not a standing humanoid|two legs")])
def test_a_four_legged_figure_is_refused(mocap_dir: Path, name: str, message: str) -> None:
    names, parents, pos = _skin_pose(mocap_dir / name)
    with pytest.raises(ValueError, match=message) as err:
        guess_roles_by_shape(names, parents, pos)
    assert "\n" not in str(err.value)


def test_a_hand_alone_is_refused() -> None:
    # A wrist with five fingers of three joints: no branch reaches 30 % of the height above the ground.
    parents = [-1] + [j for f in range(5) for j in (0, 1 + 3 * f, 2 + 3 * f)]
    pos = np.zeros((16, 3))
    for f in range(5):
        for k in range(3):
            pos[1 + 3 * f + k] = [0.02 * (f - 2), (0.03 + 0.005 * f) * (k + 1), 0.0]
    with pytest.raises(ValueError, match="legs"):
        guess_roles_by_shape([f"j{k}" for k in range(16)], np.array(parents), pos)
