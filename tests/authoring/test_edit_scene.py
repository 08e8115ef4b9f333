"""The edit scene, headless: each mode renders, and mouse gestures become undoable edits."""

from __future__ import annotations

import os
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from authoring.edit_scene import EditScene
from authoring.mocurves import EditSession
from engine.clips import default_clips

render = pytest.importorskip("engine.render")

SHOTS = Path(os.environ.get("MOCURVES_SHOTS", "/tmp"))


@pytest.fixture(scope="module")
def viewer():
    reason = render.egl_available()
    if reason is not None:
        pytest.skip(f"no headless GL here: {reason}")
    v = render.Viewer.create(headless=True, width=640, height=360)
    yield v
    v.close()


def colour_pixels(img, rgb, tol=40):
    return int(np.sum(np.all(np.abs(img.astype(int) - np.array(rgb)) < tol, axis=-1)))


def shoot(viewer, edit, name):
    scene = render.RenderScene()
    edit.draw(scene)
    viewer.camera = edit.camera
    viewer.draw(scene)
    viewer.screenshot(SHOTS / f"mocurves_{name}.png")
    return viewer.read_pixels()


def px_of(edit, point):
    return tuple(edit.camera.project(np.asarray(point)[None], *edit.size)[0])


def test_each_mode_renders_and_edits(viewer):
    walk = replace(default_clips()["walk"], root_motion=None)
    session = EditSession(walk, tau=6, sigma=0.08)
    edit = EditScene(session, viewer.size)
    edit.playing = False

    edit.key("1")
    img = shoot(viewer, edit, "points")
    assert colour_pixels(img, (255, 255, 255), 12) > 20  # the control points
    ctrl = session.control_points("l_foot")[3]
    x, y = px_of(edit, ctrl)
    assert edit.press(x, y)
    edit.release(x, y - 20)
    assert session.history == ["move l_foot control 3"]

    edit.key("2")
    foot = session.curves()["l_foot"].positions
    x, y = px_of(edit, foot[20])
    edit.move(x, y)
    img = shoot(viewer, edit, "arrows")
    assert colour_pixels(img, (230, 26, 26)) > 10  # red: arrows the falloff reaches
    assert edit.press(x, y)
    edit.release(x + 30, y)
    assert session.history[-1].startswith("rotate l_foot@")

    edit.key("3")
    x, y = px_of(edit, foot[12])
    assert edit.press(x, y)
    x2, y2 = px_of(edit, foot[16])
    edit.move(x2, y2)  # live: the preview is shown before release
    assert session.state is not session._state
    edit.release(x2, y2)
    assert session.history[-1] == "retime l_foot"
    img = shoot(viewer, edit, "timing")
    assert colour_pixels(img, (230, 26, 26)) > 5  # the held keypoint

    edit.key("4")
    pos = session.curves()["l_foot"].positions
    low = pos[np.argmin(pos[:, 1])] + np.array([0.0, 0.02, 0.0])
    a, b = px_of(edit, low + [0, 0, -0.6]), px_of(edit, low + [0, 0, 0.6])
    edit.press(*a)
    edit.move(*b)
    img = shoot(viewer, edit, "contact")
    assert colour_pixels(img, (153, 38, 217)) > 20  # the purple stroke
    edit.release(*b)
    assert session.history[-1] == "contact l_foot+r_foot", edit.message
    assert session.clip.cycle_travel()[0][2] > 0.5
    assert session.state.clip is not None and edit.message.startswith("contact:")
    shoot(viewer, edit, "contact_done")

    for _ in range(4):
        edit.key("z", ctrl=True)
    assert session.clip is walk


def test_the_panel_shows_the_walking_speed_and_the_items_speed_apart():
    from engine.render.scene import RenderScene

    walk = default_clips()["walk"]  # as `author edit walk` opens it
    edit = EditScene(EditSession(walk), (1280, 720))
    scene = RenderScene()
    edit.draw(scene)
    texts = [t.text for t in scene.texts]
    root = next(t for t in texts if t.startswith("root: "))
    assert f"travels {walk.average_speed():.2f} m/s" in root and 0.8 < walk.average_speed() < 2.0
    item = next(t for t in texts if t.startswith(f"{edit.item}: "))
    assert "along its curve" in item and "relative to the body" in item
    assert not any(t.count("m/s") == 1 and "speed " in t for t in texts)  # the old mixed "speed a–b m/s" is gone
