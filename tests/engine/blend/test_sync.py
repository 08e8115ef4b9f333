"""Phase synchronisation: one phase drives every cycle and keeps their contacts in step."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from engine.blend import BlendSpace, SyncGroup
from engine.clip import Clip
from engine.fk import forward_kinematics, world_points


def _left_foot_forward(clip: Clip, times: np.ndarray) -> np.ndarray:
    """Left foot tip z relative to the hips (positive = ahead)."""
    pose = clip.sample(times)
    wpos, wrot = forward_kinematics(clip.skeleton, pose.root, pose.rotations)
    tips = world_points(clip.skeleton, wpos, wrot)
    return tips[:, clip.skeleton.index("l_foot"), 2] - pose.root[:, 2]


def test_markers_map_to_the_shared_phase(clips: dict[str, Clip]) -> None:
    group = SyncGroup((clips["walk"], clips["run"]))
    t = group.clip_times(np.array([0.0, 0.5, 1.0, 1.25]))
    walk, run = clips["walk"].duration, clips["run"].duration
    assert np.allclose(t[:, 0], [0.0, 0.5 * walk, walk, 1.25 * walk])
    # the run's right heel strike is at 0.46 of its cycle: phase 0.5 lands there
    assert np.allclose(t[:2, 1], [0.0, 0.46 * run])
    assert np.all(np.diff(group.clip_times(np.linspace(0, 3, 301)), axis=0) > 0)


def test_cycle_duration_is_the_weighted_mean(clips: dict[str, Clip]) -> None:
    group = SyncGroup((clips["walk"], clips["run"]))
    want = 0.25 * clips["walk"].duration + 0.75 * clips["run"].duration
    assert group.cycle_duration([0.25, 0.75]) == pytest.approx(want)


def test_vectorised_root_motion_matches_the_clip(clips: dict[str, Clip]) -> None:
    group = SyncGroup((clips["walk"], clips["crouch_walk"]))
    phases = np.linspace(0.0, 2.7, 55)
    trans, _ = group.root_motion(phases)
    times = group.clip_times(phases)
    for i, ph in enumerate(phases):
        for k, clip in enumerate(group.clips):
            ref, _ = clip.sample_root_motion(float(times[i, k]))
            assert np.allclose(trans[i, k], ref, atol=1e-12), (ph, clip.name)


def test_phase_sync_keeps_a_walk_run_blend_in_step(clips: dict[str, Clip]) -> None:
    walk, run = clips["walk"], clips["run"]
    group = SyncGroup((walk, run))
    phases = np.linspace(0.0, 1.0, 120, endpoint=False)
    t = group.clip_times(phases)
    fw, fr = _left_foot_forward(walk, t[:, 0]), _left_foot_forward(run, t[:, 1])
    synced = np.corrcoef(fw, fr)[0, 1]
    # the same clips played on their own clocks drift out of step
    own = np.linspace(0.0, 3 * walk.duration, 360)
    unsynced = np.corrcoef(_left_foot_forward(walk, own), _left_foot_forward(run, own))[0, 1]
    assert synced > 0.97
    assert unsynced < 0.5
    # in the blend, the left heel strikes (foot furthest ahead) at phase 0, as in both clips
    space = BlendSpace((walk, run), np.array([[0.0], [1.0]]), ("velocity",))
    pose = space.sample(np.tile([0.5, 0.5], (len(phases), 1)), phases)
    wpos, wrot = forward_kinematics(walk.skeleton, pose.root, pose.rotations)
    ahead = world_points(walk.skeleton, wpos, wrot)[:, walk.skeleton.index("l_foot"), 2] - pose.root[:, 2]
    strike = phases[int(np.argmax(ahead))]
    assert min(strike, 1.0 - strike) < 0.03


def test_only_cycles_with_ordered_markers_sync(clips: dict[str, Clip]) -> None:
    with pytest.raises(ValueError, match="not a loop"):
        SyncGroup((replace(clips["walk"], loop=False),))
    with pytest.raises(ValueError, match="distinct"):
        SyncGroup((replace(clips["walk"], markers={"left_down": 0.2, "right_down": 0.2}),))
    # a clip without markers still plays, spread evenly
    plain = SyncGroup((replace(clips["idle"], markers={}),))
    assert np.allclose(plain.clip_times(np.array([0.5])), [0.5 * clips["idle"].duration])
