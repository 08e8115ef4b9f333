"""The whole pose's autocorrelation overrules a probe vote misled to a third of the stride."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from authoring.cycles.autocorr import pose_autocorrelation, pose_period
from authoring.cycles.extract import extract_cycle
from authoring.cycles.formats import Performance, performance_from_motion
from engine import quat
from engine.clips import default_clips
from engine.io.motion_file import MotionFile
from engine.io.units import Units
from tests.engine.io.synthetic_bvh import walk_take

FPS = 120.0


@pytest.fixture(scope="module")
def misled() -> Performance:
    """2.3 strides at 120 fps whose joints wobble at three times the stride rate, with capture noise.

    A subdued walk under a strong third harmonic: at most probe points a third of the
    stride (0.367 s) passes the "smallest period whose repetitions all match" test, and
    the old extractor cut six "cycles" there; the whole pose repeats only at 1.1 s.
    """
    walk = default_clips()["walk"]
    take = walk_take(2.3, fps=FPS)
    phase = 2 * np.pi * np.arange(take.num_frames) / FPS / walk.duration
    rng = np.random.default_rng(1)
    rot = np.array(take.rotations)
    rest = quat.identity(take.num_frames)
    for j in range(1, take.skeleton.num_joints):
        wobble = 0.3 * np.sin(3 * phase + j) + 0.06 * rng.standard_normal(take.num_frames)
        rot[:, j] = quat.mul(quat.slerp(rest, rot[:, j], 0.25), quat.from_axis_angle(np.array([1.0, 0.0, 0.0]), wobble))
    motion = MotionFile(replace(take, rotations=rot), Path("misled.bvh"), Units("m", 1.0, "given"), "test")
    return performance_from_motion(motion)


def test_the_whole_pose_repeats_at_the_stride_not_at_its_third(misled: Performance) -> None:
    traj = misled.trajectory
    values = traj.values * traj.weights()
    found = pose_period(traj, values, 8, traj.num_samples // 2)
    assert found is not None
    lag, r = found
    assert lag * traj.dt == pytest.approx(default_clips()["walk"].duration, rel=0.03) and r > 0.9
    r_all = pose_autocorrelation(traj, values, lag)
    assert r_all[round(lag / 3)] < r_all[lag]


@pytest.mark.parametrize("seed", [0, 3])
def test_a_misled_vote_gives_way_to_the_pose_period(misled: Performance, seed: int) -> None:
    result = extract_cycle(misled.trajectory, np.random.default_rng(seed))
    assert result.period == pytest.approx(default_clips()["walk"].duration, rel=0.02)
    assert result.cycles == 2 and result.spread < 0.2


def test_a_still_or_random_take_has_no_pose_period() -> None:
    from authoring.cycles.trajectory import Item, Trajectory

    rng = np.random.default_rng(0)
    traj = Trajectory.uniform(np.cumsum(rng.standard_normal((300, 4)), axis=0), 60.0, (Item("x", "scalar", 0, 4),))
    assert pose_period(traj, traj.values, 8, 150) is None
