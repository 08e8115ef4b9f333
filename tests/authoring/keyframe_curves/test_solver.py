"""The tangent-space solver on the default walk, as keyframed clip (issue 19's Done-means test)."""

from __future__ import annotations

import numpy as np
import pytest

from authoring.keyframe_curves import (
    CurveSettings,
    Drag,
    Hold,
    TangentSolver,
    curve_rig,
    retime_segment,
    segment_bounds,
)
from engine.clips import default_clips
from engine.ik import humanoid_rig
from engine.keyframes import KeyframedClip, keyframe_clip


@pytest.fixture(scope="module")
def walk() -> KeyframedClip:
    return keyframe_clip(default_clips()["walk"], every=6)


def _solver(clip: KeyframedClip) -> TangentSolver:
    return TangentSolver(clip, curve_rig(clip, humanoid_rig(clip.skeleton)))


def _limits_hold(s: TangentSolver, clip: KeyframedClip) -> None:
    """Eq. 4.7–4.9 on every segment and channel, and the sampled curves inside the channel limits."""
    c = clip.curves
    for k in range(c.times.size - 1):
        ch = np.arange(c.num_channels)
        lo, hi = segment_bounds(c, k, ch, s.rig.lower, s.rig.upper)
        n = ch.size
        th = np.concatenate([c.out_x[k], c.out_y[k], c.in_x[k + 1], c.in_y[k + 1]])
        # Only tangents the edit moved must obey the limits (the fitted input may not); they are in range here.
        moved = th != np.concatenate([s.clip.curves.out_x[k], s.clip.curves.out_y[k], s.clip.curves.in_x[k + 1],
                                      s.clip.curves.in_y[k + 1]])  # fmt: skip
        assert np.all(th[moved] >= lo[moved] - 1e-12) and np.all(th[moved] <= hi[moved] + 1e-12)
        gap = c.times[k + 1] - c.times[k]
        assert np.all(th[:n] >= 0) and np.all(th[:n] <= gap) and np.all(th[2 * n : 3 * n] >= 0)
        assert np.all(th[2 * n : 3 * n] <= gap)
    dense = clip.coordinates(np.linspace(0.0, clip.duration, 2000, endpoint=False))
    before = s.clip.coordinates(np.linspace(0.0, clip.duration, 2000, endpoint=False))
    u = np.minimum(s.rig.lower, before.min(axis=0))
    v = np.maximum(s.rig.upper, before.max(axis=0))
    assert np.all(dense >= u - 1e-9) and np.all(dense <= v + 1e-9), "a curve left its limits (Appendix A)"


def test_drag_hand_at_one_frame_keeps_feet_and_keys(walk):
    s = _solver(walk)
    sk = walk.skeleton
    frame = 15  # between keys 12 and 18
    t = frame / walk.fps
    hand = sk.index("l_hand")
    start = s.points(np.array([t]), hand, np.zeros(3))[0]
    target = start + np.array([0.05, 0.04, 0.03])
    holds = [Hold("l_foot", 0, 30), Hold("r_foot", 0, 30)]
    res = s.drag(Drag("l_hand", t, position=target), holds)
    assert res.reached
    assert np.linalg.norm(s.points(np.array([t]), hand, np.zeros(3), res.clip)[0] - target) < 1e-3
    eps = CurveSettings().epsilon
    frames = np.arange(0, 31) / walk.fps
    for name in ("l_foot", "r_foot"):
        j = sk.index(name)
        drift = np.linalg.norm(s.points(frames, j, np.zeros(3), res.clip) - s.points(frames, j, np.zeros(3)), axis=-1)
        assert drift.max() <= eps, f"{name} left its pin by {drift.max() * 1e3:.3f} mm"
    # No key added or moved; only the tangents at the dragged segment's two keys changed — on both
    # sides of each key, as unbroken tangents are one variable (§4.2.2).
    assert np.array_equal(res.clip.curves.times, walk.curves.times)
    assert np.array_equal(res.clip.curves.values, walk.curves.values)
    changed_out = np.nonzero(np.any(res.clip.curves.out_y != walk.curves.out_y, axis=1))[0]
    changed_in = np.nonzero(np.any(res.clip.curves.in_y != walk.curves.in_y, axis=1))[0]
    assert res.segment == 2 and set(changed_out) == set(changed_in) == {2, 3}
    _limits_hold(s, res.clip)
    # The edit shows at the frame it was made: the baked clip has the hand there.
    baked = res.clip.bake()
    assert baked.num_frames == 66


def test_contact_holds_a_foot_still_and_unreachable_drag_is_rejected(walk):
    # A contact needs a foot that stands (Eq. 4.6: s(t_k) = s(t_k+1)); the in-place walk's
    # stance foot slides back, so the contact is tested on the idle clip, with a drag of the
    # hips that would carry the feet along.
    idle = keyframe_clip(default_clips()["idle"], every=6)
    si = _solver(idle)
    sk = idle.skeleton
    t = 15 / idle.fps
    hips = sk.index("hips")
    start = si.points(np.array([t]), hips, np.zeros(3))[0]
    feet = [Hold("l_foot", 12, 18, contact=True), Hold("r_foot", 12, 18, contact=True)]
    free = si.drag(Drag("hips", t, position=start + [0.0, -0.03, 0.02]))
    res = si.drag(Drag("hips", t, position=start + [0.0, -0.03, 0.02]), feet)
    assert free.reached and res.reached
    planted = si.points(np.array([12 / idle.fps]), sk.index("l_foot"), np.zeros(3))[0]
    moved = si.points(np.arange(13, 18) / idle.fps, sk.index("l_foot"), np.zeros(3), free.clip)
    during = si.points(np.arange(13, 18) / idle.fps, sk.index("l_foot"), np.zeros(3), res.clip)
    assert np.linalg.norm(moved - planted, axis=-1).max() > 0.01, "without the contact the foot goes along"
    assert np.linalg.norm(during - planted, axis=-1).max() <= CurveSettings().epsilon
    s = _solver(walk)
    t = 15 / walk.fps
    start = s.points(np.array([t]), walk.skeleton.index("r_hand"), np.zeros(3))[0]
    pinned = [Hold("l_foot", 0, 30), Hold("r_foot", 0, 30)]
    far = s.drag(Drag("r_hand", t, position=start + [0.0, 3.0, 0.0]), pinned)  # an arm is not 3 m long
    assert not far.reached and far.clip is s.clip  # the thesis' rejection: stay where you were
    with pytest.raises(ValueError, match="on a key"):
        s.drag(Drag("r_hand", 12 / walk.fps, position=start))


def test_orientation_drag_and_timing_edit(walk):
    from engine import quat

    s = _solver(walk)
    t = 20 / walk.fps
    j = walk.skeleton.index("head")
    turn = quat.from_axis_angle([0.0, 1.0, 0.0], 0.2)
    _, rot = walk.pose_arrays(walk.coordinates([t]))
    from engine.fk import forward_kinematics

    _, wr = forward_kinematics(walk.skeleton, walk.pose_arrays(walk.coordinates([t]))[0][0], rot[0])
    res = s.drag(Drag("head", t, orientation=quat.mul(turn, wr[j])))
    assert res.reached
    _, wr2 = forward_kinematics(walk.skeleton, *[a[0] for a in res.clip.pose_arrays(res.clip.coordinates([t]))])
    angle = np.linalg.norm(quat.log(quat.mul(quat.mul(turn, wr[j]), quat.conjugate(wr2[j]))))
    assert angle < 1e-3 / 0.2
    # Eq. 4.12: scaling the timing changes only X tangents of that segment, within [0, Δt].
    c = retime_segment(walk.curves, t, 0.05)
    k = int(walk.curves.segment_of(t))
    gap = walk.curves.times[k + 1] - walk.curves.times[k]
    assert np.all(c.out_x[k] > walk.curves.out_x[k]) and np.all(c.out_x[k] <= gap)
    assert np.array_equal(c.out_y, walk.curves.out_y) and np.array_equal(c.values, walk.curves.values)
    mid = walk.curves.times[k] + 0.5 * gap
    assert not np.allclose(KeyframedClip(walk.name, walk.skeleton, c).coordinates([mid]), walk.coordinates([mid]))


def test_free_chain_with_broken_tangents_converges_in_few_iterations():
    # E_d measured from the drag's start tangents (not from each iterate): a free 14-joint
    # chain whose keys are all broken (E_b pulls every tangent) reaches far targets in a few
    # Gauss–Newton steps; with E_d re-measured per iterate each step closed only half of
    # E_b's gap and it took 5–7 here.
    from engine.ik import IKRig
    from engine.keyframes import BezierCurves
    from engine.skeleton import Skeleton

    n, gap = 14, 20 / 30.0
    sk = Skeleton(tuple(f"j{i}" for i in range(n)), np.arange(-1, n - 1), np.tile([0.0, 0.1, 0.0], (n, 1)),
                  np.zeros((n, 3)))  # fmt: skip
    rng = np.random.default_rng(7)
    c = 3 + 3 * n
    times = np.arange(4) * gap
    values = rng.uniform(-0.3, 0.3, (4, c))
    values[:, :3] = 0.0
    ox = np.full((4, c), gap / 3)
    oy, iy = rng.uniform(-0.1, 0.1, (4, c)), rng.uniform(-0.1, 0.1, (4, c))
    oy[:, :3] = iy[:, :3] = 0.0
    clip = KeyframedClip("chain", sk, BezierCurves(times, values, ox, oy, ox, iy), fps=30.0)
    rig = IKRig.build(sk, limits=dict.fromkeys(sk.names, (-1.5, 1.5)), root_translation=True)
    # A 10 µm tolerance: the tail shows whether the steps converge quadratically or crawl.
    # Broken as the user breaks them: each side its own variable, E_b between them (not linked).
    s = TangentSolver(clip, rig, CurveSettings(tolerance=1e-5, linked_tangents=False), frozen=range(3))
    t, tip = 1.5 * gap, np.array([0.0, 0.1, 0.0])
    iterations, far = [], []
    for _ in range(12):
        oy2, iy2 = np.array(oy), np.array(iy)
        oy2[1, 3:] += rng.uniform(-0.15, 0.15, c - 3)
        iy2[2, 3:] += rng.uniform(-0.15, 0.15, c - 3)
        moved = KeyframedClip("t", sk, clip.curves.with_tangents(ox, oy2, ox, iy2), fps=30.0)
        target = s.points(np.array([t]), n - 1, tip, moved)[0]
        far.append(np.linalg.norm(target - s.points(np.array([t]), n - 1, tip)[0]))
        res = s.drag(Drag(n - 1, t, position=target, point=tip))
        assert res.reached and res.error < s.settings.tolerance
        iterations.append(res.iterations)
    assert np.median(far) > 0.05  # far drags: several linearisations are needed
    assert np.median(iterations) <= 3 and max(iterations) <= 5, iterations


def _hand_path_after_drag(walk, linked: bool):  # type: ignore[no-untyped-def]
    s = TangentSolver(walk, _solver(walk).rig, CurveSettings(linked_tangents=linked))
    hand, t = walk.skeleton.index("l_hand"), 15 / walk.fps
    start = s.points(np.array([t]), hand, np.zeros(3))[0]
    res = s.drag(Drag("l_hand", t, position=start + np.array([0.0, 0.06, 0.05])),
                 [Hold("l_foot", 0, 65), Hold("r_foot", 0, 65)])  # fmt: skip
    assert res.reached
    return s.points(np.arange(66 * 4) / (4 * walk.fps), hand, np.zeros(3), res.clip)


def _sharpest_turn_deg(path):  # type: ignore[no-untyped-def]
    d = np.diff(path, axis=0)
    cos = np.sum(d[1:] * d[:-1], axis=1) / np.maximum(
        np.linalg.norm(d[1:], axis=1) * np.linalg.norm(d[:-1], axis=1), 1e-12
    )
    return float(np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))).max())


def test_a_drag_bends_the_path_smoothly_through_unbroken_tangents(walk):
    """Issue 38: one drag made a sharp spike. With every tangent broken only the dragged segment
    moved, kinking the path at both its keys (a 114° turn between quarter-frames for this drag);
    unbroken tangents carry the change into the neighbouring segments and the path turns at most ~52°."""
    smooth, kinked = _hand_path_after_drag(walk, True), _hand_path_after_drag(walk, False)
    assert _sharpest_turn_deg(smooth) < 70.0
    assert _sharpest_turn_deg(kinked) > 90.0  # the former behaviour, for contrast
