"""The edit session: live retiming, undo/redo bit for bit, and every edit kind through it."""

from __future__ import annotations

import numpy as np
import pytest

from authoring.mocurves import EditSession, plane_from_stroke
from engine import quat


def snapshot(session):
    st = session.state
    return (st.clip.root.copy(), st.clip.rotations.copy(), st.scales.copy(), dict(st.pins),
            None if st.clip.root_motion is None else st.clip.root_motion.translation.copy())  # fmt: skip


def same(a, b):
    return all(
        (x is None and y is None)
        or (isinstance(x, dict) and x == y)
        or (isinstance(x, np.ndarray) and x.tobytes() == y.tobytes())
        for x, y in zip(a, b, strict=True)
    )


def test_retime_drag_previews_live_and_commits_as_one_step(walk):
    s = EditSession(walk)
    start = snapshot(s)
    drag = s.begin_retime("l_foot", layer="all")
    curve = s.curves()["l_foot"]
    for t in (0.30, 0.32, 0.34):  # the drag moves; each move re-solves the warm-started QP
        drag.drag_to(15, curve.position_at(t))
        assert s.clip is not walk
    with pytest.raises(RuntimeError):
        s.rotate_arrow("l_foot", 3, [0, 0, 0.1])
    drag.commit()
    assert s.can_undo() and s.history == ["retime l_foot"]
    # Frame 15 now shows the original at 0.34 s (the curve point dragged to).
    expected = walk.sample(0.34).rotations
    assert np.max(quat.angle_between(s.clip.rotations[15], expected)) < 1e-3
    assert s.pins("l_foot") == {15}
    s.undo()
    assert same(snapshot(s), start)


def test_cancelled_drag_leaves_nothing(walk):
    s = EditSession(walk)
    drag = s.begin_retime("hips")
    drag.set_time(5, 0.2)
    drag.cancel()
    assert s.clip is walk and not s.can_undo()


def test_pins_hold_keypoints_through_later_warps(walk):
    s = EditSession(walk)
    s.retime("r_hand", {10: 0.25})
    s.retime("r_hand", {40: 0.75})
    warped_twice = s.clip
    # Keypoint 10 still shows (nearly) what it showed after the first warp.
    after_first = s._undo[-1].clip
    assert np.max(quat.angle_between(warped_twice.rotations[10], after_first.rotations[10])) < 2e-3
    assert s.pins("r_hand") == {10, 40}


def test_layers_retime_only_their_joints(walk):
    s = EditSession(walk)
    s.retime("l_foot", {20: 0.45}, layer="limb")
    sk = walk.skeleton
    limb = [sk.index(n) for n in ("l_upper_leg", "l_lower_leg", "l_foot")]
    others = [j for j in range(sk.num_joints) if j not in limb]
    assert s.clip.rotations[:, others].tobytes() == walk.rotations[:, others].tobytes()
    assert s.clip.root.tobytes() == walk.root.tobytes()
    assert not np.allclose(s.clip.rotations[:, limb], walk.rotations[:, limb])


def test_undo_restores_exactly_after_every_kind_of_edit(sliding_walk):
    s = EditSession(sliding_walk, tau=5, sigma=0.1)
    states = [snapshot(s)]
    s.rotate_arrow("head", 7, [0.2, 0.0, 0.0])
    states.append(snapshot(s))
    s.scale_arrow("l_hand", 30, 0.4)
    states.append(snapshot(s))
    s.move_control_point("r_hand", 2, [0.0, 0.05, 0.0])
    states.append(snapshot(s))
    s.retime("hips", {12: 0.25})
    states.append(snapshot(s))
    sk = sliding_walk.skeleton
    s.add_contact(["l_foot", "r_foot"], plane_from_stroke([-1, 0.08, 0], [1, 0.08, 0], [0, 0, -1], [0, 1, 0]))
    states.append(snapshot(s))
    assert len(s.history) == 5 and sk.num_joints == 17
    for k in range(len(states) - 1, 0, -1):
        assert same(snapshot(s), states[k])
        assert s.undo()
    assert same(snapshot(s), states[0]) and not s.undo()
    for k in range(1, len(states)):
        assert s.redo()
        assert same(snapshot(s), states[k])
    assert not s.redo()
    s.undo()
    s.scale_arrow("head", 0, 0.1)  # a new edit drops the redo branch
    assert not s.can_redo()


def test_bad_input_is_refused_and_loses_nothing(walk):
    s = EditSession(walk)
    before = snapshot(s)
    with pytest.raises(ValueError):
        s.rotate_arrow("tail", 3, [0, 0, 1])
    with pytest.raises(ValueError):
        s.rotate_arrow("head", 3, [0, np.nan, 1])
    with pytest.raises(ValueError):
        s.set_pins("head", [999])
    assert same(snapshot(s), before) and not s.can_undo()
    with pytest.raises(ValueError, match="not a loop"):
        EditSession(walk.__class__(**{**walk.__dict__, "loop": False}))
