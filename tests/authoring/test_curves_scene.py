"""The Motion Curves scene as an animator uses it: a walk from four key poses, one drag, the timeline, the framing."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from authoring.curves_scene import CurvesScene
from authoring.keyframe_curves.session import CurveSession
from authoring.keypose_script import HAND_DRAG_FRAME, WALK_KEYS, walk_script

EPS = 1e-4  # metres: the tangent solver's ε for held points (Eq. 4.11), per held frame
SHOTS = Path(os.environ.get("CURVES_SHOTS", "/tmp"))


def _author_walk(size=(1280, 720)):  # type: ignore[no-untyped-def]
    """Run the scripted animator through the scene's operations; the clip just before the hand drag too."""
    session = CurveSession.from_spec("rest")
    scene = CurvesScene(session, size, "l_hand")
    before_drag = None
    for ops in walk_script(scene):
        for op in ops:
            if op[0] == "press" and session.history[-1:] == ["pin r_foot 0-59"] and before_drag is None:
                before_drag = session.clip
            scene.apply(op)
    return scene, session, before_drag


@pytest.fixture(scope="module")
def authored():
    return _author_walk()


def test_a_walk_from_four_key_poses_loops_and_one_hand_drag_keeps_both_feet_pinned(authored):
    scene, session, before = authored
    clip = session.clip
    assert session.key_frames() == [*WALK_KEYS, 60]
    posed = [h for h in session.history if h.startswith("pose")]
    assert {h.split("@key ")[1] for h in posed} == {"0", "1", "2", "3"} and len(posed) == 20
    assert session.history[-1] == f"drag l_hand@{HAND_DRAG_FRAME}"
    sk = clip.skeleton
    times = np.arange(clip.num_frames + 1) / clip.fps  # every frame and the seam again
    pts = {j: session.solver.points(times, sk.index(j), np.zeros(3), clip) for j in ("l_foot", "r_foot", "l_hand")}
    old = {j: session.solver.points(times, sk.index(j), np.zeros(3), before) for j in ("l_foot", "r_foot", "l_hand")}
    # The hand's path was edited by the one drag…
    assert np.linalg.norm(pts["l_hand"][HAND_DRAG_FRAME] - old["l_hand"][HAND_DRAG_FRAME]) > 0.02
    # …and both feet stayed on their paths at every frame, within ε.
    for foot in ("l_foot", "r_foot"):
        assert np.linalg.norm(pts[foot] - old[foot], axis=1).max() <= EPS, foot
    # It loops: the seam key is one pose, and no joint jumps or kinks across the seam.
    assert np.array_equal(clip.curves.values[0], clip.curves.values[-1])
    for p in pts.values():
        assert np.linalg.norm(p[-1] - p[0]) < 1e-12
        step = np.diff(p, axis=0)
        accel = np.linalg.norm(np.diff(np.vstack([step, step[:1]]), axis=0), axis=1)  # wraps across the seam
        assert accel[-1] <= 1.5 * accel[:-1].max() + 1e-9
    # The key poses are a walk: at the contacts one foot is ahead of the other (+z), swapped half a cycle on.
    z = {f: pts[f][:, 2] for f in ("l_foot", "r_foot")}
    assert z["l_foot"][0] - z["r_foot"][0] > 0.3 and z["r_foot"][30] - z["l_foot"][30] > 0.3


def test_the_timeline_adds_moves_and_deletes_keys_with_undo():
    session = CurveSession.from_spec("rest")
    scene = CurvesScene(session, (640, 360), "l_hand")
    line = scene.timeline()
    y = line.top + line.height / 2
    scene.apply(["press", line.x_of(20), y, False])
    scene.apply(["release", line.x_of(20), y])
    assert scene.frame == 20
    scene.apply(["key", "k", False, False])
    assert session.key_frames() == [0, 20, 60]
    scene.apply(["press", line.x_of(20), y, False])  # grab the new key's diamond…
    scene.apply(["move", line.x_of(33), y])
    scene.apply(["release", line.x_of(33), y])  # …and slide it to frame 33
    assert session.key_frames() == [0, 33, 60] and session.history[-1] == "move key 1 to 33"
    scene.apply(["key", "x", False, False])
    assert session.key_frames() == [0, 60]
    scene.apply(["key", "z", True, False])
    assert session.key_frames() == [0, 33, 60]
    scene.apply(["key", "x", False, False])
    scene.apply(["key", "x", False, False])  # nothing left here to delete: said, not raised
    assert "no key here" in scene.message


def _grip_px(scene):  # type: ignore[no-untyped-def]
    from authoring.curves_handles import orientation_sticks

    j = scene.session.clip.skeleton.index(scene.joint)
    _, tip, rot = orientation_sticks(scene.session, scene.frame_times()[scene.frame : scene.frame + 1], j)
    return scene.camera.project(tip, *scene.size)[0], rot[0]


def test_the_orientation_grip_turns_the_joint_in_place_between_keys_and_at_a_key():
    from engine import quat

    session = CurveSession.from_spec("walk")
    scene = CurvesScene(session, (1280, 720))
    scene.frame = 15  # between keys 12 and 18: the tangent solver turns it
    px, before = _grip_px(scene)
    hand_at = scene.trajectory()[15].copy()
    for op in (["press", *px, False], ["move", px[0] + 30, px[1]], ["release", px[0] + 30, px[1]]):
        scene.apply(op)
    _, after = _grip_px(scene)
    assert session.history == ["turn l_hand@15"] and np.degrees(quat.angle_between(before, after)) > 20.0
    assert np.linalg.norm(scene.trajectory()[15] - hand_at) < 0.05  # turned in place, not carried off
    rest = CurveSession.from_spec("rest")
    rest.add_key(30)
    scene = CurvesScene(rest, (1280, 720), "l_hand")
    scene.frame = 30  # a key: the static IK turns it
    px, before = _grip_px(scene)
    for op in (["press", *px, False], ["move", px[0], px[1] - 40], ["release", px[0], px[1] - 40]):
        scene.apply(op)
    _, after = _grip_px(scene)
    assert rest.history[-1] == "turn l_hand@30" and np.degrees(quat.angle_between(before, after)) > 20.0


def test_the_spacing_handle_scales_the_timing_at_the_frame():
    """Fig. 4.4 right: dragging the magenta handle under the current frame to the right moves the frames apart
    there (Eq. 4.12, σ > 0): the time tangents around it lengthen and the undo restores them."""
    session = CurveSession.from_spec("walk")
    scene = CurvesScene(session, (1280, 720))
    scene.frame = 15
    before = session.clip.curves
    px = scene.camera.project(scene.spacing_handle()[None], 1280, 720)[0]
    for op in (["press", *px, False], ["move", px[0] + 50, px[1]], ["release", px[0] + 50, px[1]]):
        scene.apply(op)
    after = session.clip.curves
    assert session.history == ["retime +0.010"]
    assert after.out_x[2].min() > before.out_x[2].max() - 1e-12 and np.all(after.in_x[3] >= before.in_x[3])
    assert np.any(after.out_x[2] > before.out_x[2]) and np.array_equal(after.values, before.values)
    assert session.undo() and session.clip.curves is before


def test_the_camera_frames_the_whole_puppet_in_a_small_window():
    """Issue 38: the head was cropped. Every capsule surface point of the walk, at every frame,
    projects inside the window, below the panel's three lines and above the timeline."""
    from engine.fk import forward_kinematics
    from engine.render.extract import puppet_capsules

    for size in ((640, 360), (1280, 720), (480, 640)):
        scene = CurvesScene(CurveSession.from_spec("walk"), size)
        clip = scene.session.clip
        roots, rots = clip.pose_arrays(clip.coordinates(scene.frame_times()))
        for f in range(clip.num_frames):
            pos, wrot = forward_kinematics(clip.skeleton, roots[f], rots[f])
            a, b, r, _ = puppet_capsules(clip.skeleton, pos, wrot)
            top = np.vstack([a, b]) + np.concatenate([r, r])[:, None] * np.array([0.0, 1.0, 0.0])
            px = scene.camera.project(top, *size)
            assert px[:, 1].min() > 0.1 * size[1] and px[:, 1].max() < scene.timeline().top, (size, f)
            assert px[:, 0].min() > 0 and px[:, 0].max() < size[0], (size, f)


render = pytest.importorskip("engine.render")


@pytest.fixture(scope="module")
def viewer():
    reason = render.egl_available()
    if reason is not None:
        pytest.skip(f"no headless GL here: {reason}")
    v = render.Viewer.create(headless=True, width=640, height=360)
    yield v
    v.close()


def _shoot(viewer, scene, name):  # type: ignore[no-untyped-def]
    rs = render.RenderScene()
    scene.draw(rs)
    viewer.camera = scene.camera
    viewer.draw(rs)
    path = SHOTS / f"curves_{name}.png"
    viewer.screenshot(path)
    from PIL import Image

    return np.asarray(Image.open(path).convert("RGB")).astype(int)


def _near(img, rgb, tol=40):  # type: ignore[no-untyped-def]
    return np.all(np.abs(img - np.array(rgb)) < tol, axis=-1)


def test_render_shows_keys_on_the_timeline_and_joint_handles_at_a_key(viewer):
    from authoring.curves_timeline import CURSOR_RGB, KEY_RGB

    scene, session, _ = _author_walk((640, 360))
    scene.frame = 15  # a key: the joints are the IK's handles (blue dots)
    img = _shoot(viewer, scene, "key_pose")
    line = scene.timeline()
    strip = img[line.top : line.top + line.height]
    for f in session.key_frames()[:-1]:  # an orange diamond at each key (the seam once)
        x = int(round(line.x_of(f)))
        assert _near(strip[:, max(x - 3, 0) : x + 4], KEY_RGB).sum() >= 6, f
    x15, x8 = int(round(line.x_of(15))), int(round(line.x_of(8)))
    assert _near(strip[:, x15 - 1 : x15 + 2], CURSOR_RGB).sum() >= 3  # the cursor on key 15
    assert not _near(strip[:, x8 - 3 : x8 + 4], KEY_RGB).any()  # no key at frame 8
    handles = _near(img[: line.top], (26, 140, 242), tol=45).sum()
    scene.frame = 22  # between keys: no joint handles
    img2 = _shoot(viewer, scene, "between_keys")
    assert handles >= 60 and _near(img2[: line.top], (26, 140, 242), tol=45).sum() < handles // 4
    grip, _ = _grip_px(scene)  # the teal orientation grip at the current frame's stick
    x, y = int(round(grip[0])), int(round(grip[1]))
    assert _near(img2[y - 5 : y + 6, x - 5 : x + 6], (26, 191, 178), tol=50).sum() >= 20


def test_a_hold_naming_its_joint_by_index_draws_as_one_naming_it():
    """``Hold.joint`` is a name or an index (the solver reads both); the scene looked an index up as a
    name and drawing raised ``KeyError``. Broken by reverting the scene to ``skeleton.index(h.joint)``."""
    from authoring.keyframe_curves.solver import Hold
    from engine.render.scene import RenderScene

    rest = CurveSession.from_spec("rest")
    drawn = []
    for joint in ("r_foot", rest.clip.skeleton.index("r_foot")):
        scene = RenderScene()
        CurvesScene(CurveSession(rest.clip, holds=(Hold(joint, 0, 10),)), (640, 480), "l_hand").draw(scene)
        drawn.append(scene.points.data.copy())
    assert len(drawn[0]) > 0
    np.testing.assert_array_equal(drawn[0], drawn[1])
