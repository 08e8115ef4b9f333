"""Get-up: settle detection, lying orientation, and a pop-free blend into the get-up clip."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from engine import quat
from engine.app import App
from engine.clip import Clip
from engine.components import LocalPose
from engine.ecs import World
from engine.pose import Pose
from engine.ragdoll import (
    GetUpBlend,
    LyingOrientation,
    PhysicsWorld,
    Ragdoll,
    RagdollMode,
    lying_heading,
    lying_orientation,
    max_rotation_jump,
    pick_get_up_clip,
    settled,
)
from engine.ragdoll.getup import SETTLE_FRAMES

X = np.array([1.0, 0.0, 0.0])
Y = np.array([0.0, 1.0, 0.0])


def test_lying_orientation_from_the_pelvis() -> None:
    on_back = quat.from_axis_angle(X, -np.pi / 2)
    assert lying_orientation(on_back) is LyingOrientation.FACE_UP
    assert lying_orientation(quat.from_axis_angle(X, np.pi / 2)) is LyingOrientation.FACE_DOWN
    on_side = quat.mul(quat.from_axis_angle(np.array([0.0, 0.0, 1.0]), np.pi / 2), quat.identity())
    assert lying_orientation(on_side) is LyingOrientation.SIDE
    # heading follows the spine on the ground, whatever the yaw
    turned = quat.mul(quat.from_axis_angle(Y, 0.7), on_back)
    diff = lying_heading(turned) - lying_heading(on_back)
    assert np.angle(np.exp(1j * diff)) == pytest.approx(0.7)


def test_pick_get_up_clip(get_up_clips: dict[str, Clip]) -> None:
    clip = pick_get_up_clip(get_up_clips, LyingOrientation.FACE_UP)
    assert clip.name.startswith("get_up")
    with pytest.raises(KeyError, match="get-up"):
        pick_get_up_clip({}, LyingOrientation.SIDE)


def test_blend_never_pops(skeleton, get_up_clips: dict[str, Clip]) -> None:  # type: ignore[no-untyped-def]
    clip = pick_get_up_clip(get_up_clips, LyingOrientation.FACE_UP)
    rng = np.random.default_rng(3)
    start_rot = quat.normalize(clip.rotations[0] + rng.normal(0, 0.25, clip.rotations[0].shape))
    start_rot[0] = quat.mul(quat.from_axis_angle(Y, 2.0), clip.rotations[0, 0])
    start = Pose(np.array([1.0, 0.12, -2.0]), start_rot)
    g = GetUpBlend(start, clip, 1 / 60)
    frames = []
    while not g.done:
        frames.append(g.advance())
    rots = np.stack([f.rotations for f in frames])
    np.testing.assert_allclose(rots[0], start.rotations, atol=1e-12)
    assert max_rotation_jump(rots) <= g.clip_jump
    # aligned with the body: same heading and place, ends in the clip's last (idle) frame
    assert lying_heading(frames[g.blend_frames].rotations[0]) == pytest.approx(lying_heading(start_rot[0]))
    np.testing.assert_allclose(frames[-1].rotations[1:], clip.rotations[-1, 1:], atol=1e-9)
    np.testing.assert_allclose(
        frames[-1].root[[0, 2]] - start.root[[0, 2]],
        quat.rotate(g.heading(), clip.root[-1] - clip.root[0])[[0, 2]],
        atol=1e-9,
    )


def test_drop_settle_and_get_up(
    make_app: Callable[..., tuple[App, int]], get_up_clips: dict[str, Clip], idle_rotations: np.ndarray
) -> None:
    tilt = quat.identity(17)
    tilt[0] = quat.from_axis_angle(X, -0.35)
    app, e = make_app(np.array([0.0, 1.95, 0.0]), tilt)
    pw = app.world.resource(PhysicsWorld)
    rd = app.world.get(e, Ragdoll)
    state: dict[str, object] = {"blend": None, "rest": None, "start": None, "poses": []}

    def get_up_state(world: World) -> None:  # what the puppet state machine does
        if state["blend"] is None and settled(rd):
            pose = pw.pose(e)
            orient = lying_orientation(pose.rotations[0])
            state["blend"] = GetUpBlend(pose, pick_get_up_clip(get_up_clips, orient), world.dt)
            state["start"] = world.frame
            rd.set_mode(RagdollMode.ANIMATED, immediate=True)
        g = state["blend"]
        if isinstance(g, GetUpBlend) and not g.done:
            p = g.advance()
            lp = world.get(e, LocalPose)
            lp.root, lp.rotations = p.root, p.rotations
            state["poses"].append(p.rotations)  # type: ignore[attr-defined]

    app.add_system("statemachine", get_up_state)
    for _ in range(600):
        app.step()
        if state["rest"] is None and rd.still_frames == 1:
            state["rest"] = app.world.frame
        if state["rest"] is not None and rd.still_frames == 0 and state["start"] is None:
            state["rest"] = None  # it moved again
        g = state["blend"]
        if isinstance(g, GetUpBlend) and g.done:
            break
    assert isinstance(state["blend"], GetUpBlend) and state["blend"].done
    assert state["start"] - state["rest"] <= SETTLE_FRAMES + 1  # type: ignore[operator]
    rots = np.stack(state["poses"])  # type: ignore[arg-type]
    assert max_rotation_jump(rots) <= state["blend"].clip_jump
    clip = state["blend"].clip
    final = app.world.get(e, LocalPose)
    np.testing.assert_allclose(final.rotations[1:], clip.rotations[-1, 1:], atol=1e-9)
    assert final.root[1] == pytest.approx(clip.root[-1, 1])
    assert np.degrees(quat.angle_between(final.rotations[1:], idle_rotations[1:])).max() < 1.0
    assert pw.data is None or np.isfinite(pw.data.qpos).all()  # back to animated, alone: out of the model
    assert not pw.in_model(e)


def test_get_up_rejects_bad_start(skeleton, get_up_clips: dict[str, Clip]) -> None:  # type: ignore[no-untyped-def]
    clip = next(iter(get_up_clips.values()))
    with pytest.raises(ValueError, match="NaN"):
        GetUpBlend(Pose(np.array([np.nan, 0, 0]), quat.identity(17)), clip, 1 / 60)
    with pytest.raises(ValueError, match="joints"):
        GetUpBlend(Pose(np.zeros(3), quat.identity(5)), clip, 1 / 60)
