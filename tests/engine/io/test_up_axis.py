"""Up axis judged by the figure: a Z-up BVH as Blender writes it stands up, exactly; ``--up`` overrides."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from engine import quat
from engine.clip import Clip
from engine.fk import forward_kinematics
from engine.io.motion_file import MotionFileError, load_motion
from engine.io.up_axis import given_up, judge_up, stood_up
from tests.engine.io.synthetic_bvh import blender_bvh, walk_take


def _world(clip: Clip) -> np.ndarray:
    return forward_kinematics(clip.skeleton, clip.root, clip.rotations, clip.translations)[0]


def test_a_blender_z_up_bvh_stands_up_exactly(tmp_path: Path) -> None:
    take = walk_take()
    motion = load_motion(blender_bvh(tmp_path / "blender.bvh", take))
    assert motion.up.name == "z" and "along z" in motion.up.basis
    assert motion.units.name == "m"
    assert np.abs(_world(motion.clip) - _world(take)).max() < 1e-5  # every joint where the Y-up take has it
    summary = motion.summary()
    assert summary["up"] == "z" and summary["height"] == pytest.approx(motion.height, abs=1e-4)
    assert 1.4 < motion.height < 2.0
    # The rest pose stands up too (the editors and the unit judge look at it).
    rest = forward_kinematics(
        motion.clip.skeleton, motion.clip.skeleton.offsets[0], quat.identity(motion.clip.skeleton.num_joints)
    )[0]
    assert np.ptp(rest[:, 1]) > np.ptp(rest[:, 2])


def test_up_given_overrides_the_judgement(tmp_path: Path) -> None:
    path = blender_bvh(tmp_path / "blender.bvh", walk_take())
    lying = load_motion(path, up="y")
    assert lying.up.name == "y" and lying.up.basis == "given" and lying.height < 0.8  # the stride, not the figure
    with pytest.raises(MotionFileError, match="unknown up axis 'w'"):
        load_motion(path, up="w")


def test_a_y_up_capture_keeps_its_axes_and_a_crawl_is_not_stood_up() -> None:
    take = walk_take()
    assert judge_up(take).name == "y"
    # The same figure lying head first along its travel (a crawl in a Y-up file) keeps Y.
    flat = quat.from_axis_angle(np.array([1.0, 0.0, 0.0]), np.float64(np.pi / 2))  # head towards +Z, the travel
    crawl = replace(
        take,
        root=quat.rotate(flat, take.root - take.root[0]) * [1, 1, 0] + take.root * [0, 0, 1],
        rotations=np.concatenate([quat.mul(flat, take.rotations[:, :1]), take.rotations[:, 1:]], axis=1),
    )
    assert judge_up(crawl).name == "y" and "travels" in judge_up(crawl).basis


def test_an_upside_down_file_is_turned_half_round_x() -> None:
    take = walk_take(1)
    up = stood_up(take, given_up("-y"))
    assert np.allclose(up.root, take.root * [1.0, -1.0, -1.0])
    assert np.allclose(_world(up), _world(take) * [1.0, -1.0, -1.0])
