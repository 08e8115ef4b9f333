"""Key edits and key posing (thesis §4.2.5, §4.3.1): what each does to the motion, and its limits."""

from __future__ import annotations

import numpy as np
import pytest

from authoring.keyframe_curves.keys import delete_key, insert_key, key_frames, move_key, rest_clip, set_key_channels
from authoring.keyframe_curves.posing import pose_key, posing_rig
from authoring.keyframe_curves.session import CurveSession, standing_root
from engine.clips import default_clips
from engine.fk import forward_kinematics
from engine.keyframes import keyframe_clip


@pytest.fixture(scope="module")
def walk():
    return keyframe_clip(default_clips()["walk"], every=6)


def _joints(clip, k):  # type: ignore[no-untyped-def]
    root, rot = clip.pose_arrays(clip.curves.values[k][None])
    return forward_kinematics(clip.skeleton, root[0], rot[0])[0]


def test_insert_key_keeps_the_motion_and_delete_and_move_respect_neighbours(walk):
    more = insert_key(walk, 8.4 / walk.fps)  # off a frame: every channel splits at its own λ
    assert more.curves.times.size == walk.curves.times.size + 1
    assert np.abs(more.bake().rotations - walk.bake().rotations).max() < 1e-12
    assert np.abs(more.bake().root - walk.bake().root).max() < 1e-12
    fewer = delete_key(more, 2)
    assert np.array_equal(fewer.curves.times, walk.curves.times)
    moved = move_key(walk, 3, 20 / walk.fps)
    assert list(key_frames(moved))[3] == 20 and np.array_equal(moved.curves.values, walk.curves.values)
    with pytest.raises(ValueError, match="bound the clip"):
        delete_key(walk, 0)
    with pytest.raises(ValueError, match="frames from its neighbours"):
        move_key(walk, 3, 13 / walk.fps)  # one frame from key 2 (frame 12)
    with pytest.raises(ValueError, match="frames to its neighbours"):
        insert_key(walk, 13 / walk.fps)


def test_posing_the_seam_key_poses_both_ends_of_a_loop(walk):
    new = set_key_channels(walk, 0, walk.curves.values[4])
    assert np.array_equal(new.curves.values[0], new.curves.values[-1])
    # The seam's tangents are one: the slope leaving frame 0 is the slope arriving at the end.
    c = new.curves
    assert np.allclose(c.out_y[0] / c.out_x[0], c.in_y[-1] / c.in_x[-1])


def test_pose_key_holds_pins_within_eps_and_keeps_limits():
    sk = default_clips()["walk"].skeleton
    clip = insert_key(rest_clip(sk, root=standing_root(sk)), 0.5)
    before = _joints(clip, 1)
    foot = sk.index("l_foot")
    res = pose_key(clip, 1, "l_foot", before[foot] + np.array([0.0, 0.05, 0.3]), ("r_foot",))
    after = _joints(res.clip, 1)
    assert res.reached and np.linalg.norm(after[foot] - (before[foot] + [0.0, 0.05, 0.3])) < 1e-3
    # The static IK's ε (1e-4 m) bounds each coordinate of a pinned point's drift.
    assert np.abs(after[sk.index("r_foot")] - before[sk.index("r_foot")]).max() <= 1e-4
    rig = posing_rig(sk)
    c, _ = rig.to_coordinates(
        res.clip.curves.values[1][:3], res.clip.pose_arrays(res.clip.curves.values[1][None])[1][0]
    )
    assert rig.within_limits(c, tol=1e-6)


def test_an_unreachable_target_keeps_the_closest_pose_with_its_residual():
    sk = default_clips()["walk"].skeleton
    clip = insert_key(rest_clip(sk, root=standing_root(sk)), 0.5)
    hand = sk.index("l_hand")
    start = _joints(clip, 1)[hand]
    target = start + np.array([0.0, 1.5, 0.0])  # far over the head, feet pinned
    res = pose_key(clip, 1, "l_hand", target, ("l_foot", "r_foot"))
    reached = _joints(res.clip, 1)[hand]
    assert not res.reached and res.residual > 0.1
    assert abs(np.linalg.norm(reached - target) - res.residual) < 1e-6  # the residual is the miss shown
    assert np.linalg.norm(reached - target) < np.linalg.norm(start - target) - 0.3  # the closest pose, not the old one


def test_session_key_edits_are_undo_steps_restoring_exact_arrays():
    s = CurveSession.from_spec("rest", duration=1.0)
    base = s.clip
    s.add_key(30)
    s.pose(1, "r_hand", np.array([-0.3, 1.3, 0.2]))
    s.move_key(1, 24)
    assert s.key_frames() == [0, 24, 60] and s.history == ["add key 30", "pose r_hand@key 1", "move key 1 to 24"]
    posed = s.clip
    assert s.undo() and s.undo() and s.undo() and s.clip is base
    assert s.redo() and s.redo() and s.redo() and s.clip is posed
    s.delete_key(1)
    assert s.key_frames() == [0, 60]


def test_an_unreachable_curve_drag_keeps_its_closest_solution(walk):
    """§4.4: a drag between keys that cannot reach keeps the closest solution (an undo step), residual reported."""
    s = CurveSession(walk)
    s.toggle_hold("l_foot", 0, 65)
    s.toggle_hold("r_foot", 0, 65)  # the feet stay: the body cannot rise with the hand
    hand, t = walk.skeleton.index("l_hand"), 15 / walk.fps
    start = s.solver.points(np.array([t]), hand, np.zeros(3))[0]
    target = start + np.array([0.0, 1.0, 0.0])  # a metre up, three frames from the keys, feet held
    res = s.drag("l_hand", t, position=target)
    assert not res.reached and s.history[-1] == "drag l_hand@15"
    now = s.solver.points(np.array([t]), hand, np.zeros(3), s.clip)[0]
    assert np.linalg.norm(now - target) < np.linalg.norm(start - target) - 0.05
    assert abs(np.linalg.norm(now - target) - res.closest_error) < 1e-9
    for foot in ("l_foot", "r_foot"):  # the closest solution keeps the pins (ε = 0.1 mm)
        j = walk.skeleton.index(foot)
        frames = np.arange(66) / walk.fps
        drift = s.solver.points(frames, j, np.zeros(3), s.clip) - s.solver.points(frames, j, np.zeros(3), walk)
        assert np.linalg.norm(drift, axis=1).max() <= 1e-4
