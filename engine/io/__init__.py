"""Motion import/export: BVH read/write, glTF 2.0 read/write, retargeting onto the puppet.

Everything here turns outside files into engine assets (:class:`~engine.skeleton.Skeleton`,
:class:`~engine.clip.Clip`) and back; nothing runs per frame. A downloaded clip reaches a
blend space as ``retarget(read_bvh(path).to_clip(skip_frames=...), humanoid_skeleton())``, or,
with units, glTF animations and name maps decided the way the commands do,
``to_puppet(load_motion(path).clip)``.
"""

from engine.io.bvh import BvhError, BvhMotion, BvhWarning, parse_bvh, read_bvh, write_bvh
from engine.io.bvh_convert import bvh_to_clip, clip_to_bvh, detect_tpose_frames, detect_unit_scale, skip_leading_tpose
from engine.io.gltf import GltfAnimation, GltfAsset, GltfError, GltfSkin, read_gltf
from engine.io.gltf_clip import gltf_clip, gltf_skeleton, load_gltf_clips
from engine.io.gltf_write import write_gltf
from engine.io.joint_maps import JOINT_MAPS, guess_joint_map
from engine.io.motion_file import MotionFile, MotionFileError, load_joint_map, load_motion, to_puppet
from engine.io.retarget import RetargetWarning, retarget
from engine.io.units import UNITS, judge_units

__all__ = [
    "BvhError",
    "BvhWarning",
    "BvhMotion",
    "parse_bvh",
    "read_bvh",
    "write_bvh",
    "bvh_to_clip",
    "clip_to_bvh",
    "detect_tpose_frames",
    "detect_unit_scale",
    "skip_leading_tpose",
    "GltfAnimation",
    "GltfAsset",
    "GltfError",
    "GltfSkin",
    "read_gltf",
    "gltf_clip",
    "gltf_skeleton",
    "load_gltf_clips",
    "write_gltf",
    "JOINT_MAPS",
    "guess_joint_map",
    "retarget",
    "RetargetWarning",
    "MotionFile",
    "MotionFileError",
    "load_motion",
    "load_joint_map",
    "to_puppet",
    "UNITS",
    "judge_units",
]
