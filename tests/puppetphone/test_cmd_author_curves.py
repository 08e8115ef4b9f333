"""``puppetphone author curves``: the scripted drag as a user runs it, files it writes, bad input."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np


def _run(tmp_path, *args):  # type: ignore[no-untyped-def]
    env = dict(os.environ, SDL_VIDEODRIVER="dummy", SDL_AUDIODRIVER="dummy")
    return subprocess.run([sys.executable, "-m", "puppetphone", "author", "curves", *args], capture_output=True,
                          text=True, env=env, cwd=tmp_path, timeout=300)  # fmt: skip


def test_scripted_drag_saves_keys_and_exports(tmp_path):
    from authoring.keyframe_curves.session import load_curves
    from engine.clipfile import load_clip
    from engine.clips import default_clips
    from engine.keyframes import keyframe_clip

    out = tmp_path / "walk_curves.ppclip"
    done = _run(tmp_path, "walk", "--headless", "--script", "drag", "--frames", "50", "--screenshot", "after.png",
                "-o", str(out), "--export", str(tmp_path / "walk.glb"))  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert "drag l_hand@15" in done.stdout
    assert (tmp_path / "after.png").stat().st_size > 10_000 and (tmp_path / "walk.glb").exists()
    edited = load_curves(out)
    original = keyframe_clip(default_clips()["walk"], every=6)
    # Same keys, new tangents; the saved .ppclip is the edited curves baked.
    assert np.array_equal(edited.curves.times, original.curves.times)
    assert np.array_equal(edited.curves.values, original.curves.values)
    assert not np.array_equal(edited.curves.out_y, original.curves.out_y)
    # (loading renormalises the rotations, which may change their last bit)
    assert np.allclose(load_clip(out).rotations, edited.bake().rotations, rtol=0.0, atol=1e-12)
    from engine.io.gltf_cubic import read_gltf_cubic

    exported = read_gltf_cubic(tmp_path / "walk.glb")  # the edit's key slopes, as CUBICSPLINE
    slope = lambda c: c.out_y[:-1] / c.out_x[:-1]  # noqa: E731
    # (a time tangent the edit took to 0 is a vertical slope glTF cannot hold; it is floored)
    usable = edited.curves.out_x[:-1] > 0.01 * np.diff(edited.curves.times)[:, None]
    assert np.allclose(slope(exported.curves)[usable], slope(edited.curves)[usable], atol=1e-4)
    assert np.allclose(exported.curves.values, edited.curves.values, atol=1e-6)


def test_bad_clip_and_mismatched_side_file_are_one_line_errors(tmp_path):
    done = _run(tmp_path, "no_such_clip", "--headless", "--frames", "1")
    assert done.returncode == 2 and "neither a .ppclip file nor a default clip" in done.stderr
    assert "Traceback" not in done.stderr
    from authoring.keyframe_curves.session import CurveFileError, load_curves, save_curves
    from engine.clips import default_clips
    from engine.keyframes import keyframe_clip

    kc = keyframe_clip(default_clips()["run"], every=6)
    save_curves(kc, tmp_path / "a.ppclip")
    save_curves(keyframe_clip(default_clips()["walk"], every=6), tmp_path / "b.ppclip")
    (tmp_path / "b.ppkeys").write_bytes((tmp_path / "a.ppkeys").read_bytes())
    import pytest

    with pytest.raises(CurveFileError, match="another version"):
        load_curves(tmp_path / "b.ppclip")
    back = load_curves(tmp_path / "a.ppclip")
    for name in ("times", "values", "out_x", "out_y", "in_x", "in_y"):
        assert np.array_equal(getattr(back.curves, name), getattr(kc.curves, name))
    (tmp_path / "a.ppkeys").write_text("{not json")
    done = _run(tmp_path, str(tmp_path / "a.ppclip"), "--headless", "--frames", "1")
    assert done.returncode == 2 and "unreadable" in done.stderr and "Traceback" not in done.stderr


def test_scene_drag_undo_redo_and_holds():
    from authoring.curves_scene import CurvesScene
    from authoring.keyframe_curves.session import CurveSession

    session = CurveSession.from_spec("walk")
    scene = CurvesScene(session, (640, 360))
    scene.key("p")  # pin the hand at frames 0–7 …
    scene.key("p")  # … and remove it again
    assert session.holds == () and len(session.history) == 2
    scene.frame = 15
    px = scene.camera.project(scene.trajectory()[15][None], 640, 360)[0]
    assert scene.press(*px)
    scene.move(px[0] - 20, px[1] - 25)
    scene.release(px[0] - 20, px[1] - 25)
    moved = scene.trajectory()
    assert session.history[-1] == "drag l_hand@15"
    assert session.undo()
    assert np.linalg.norm(scene.trajectory()[15] - moved[15]) > 0.01
    assert session.redo() and np.array_equal(scene.trajectory(), moved)
    scene.key("right")  # turn the hand at frame 15: one more undo step
    assert session.history[-1].startswith("drag l_hand")


def test_scripted_walk_records_and_replays_with_verify(tmp_path):
    """``author curves rest --script walk --record`` then ``replay --verify``: every step's state matches.

    The first 120 steps: keys added on the timeline, the first two key poses posed with pins held."""
    from authoring.keyframe_curves.session import load_curves

    rec = tmp_path / "walk.rec"
    out = tmp_path / "walk_keys.ppclip"
    done = _run(tmp_path, "rest", "--headless", "--script", "walk", "--frames", "120", "--record", str(rec),
                "-o", str(out), "--size", "640x360")  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert "add key 15" in done.stdout and "pin r_foot 0-7" in done.stdout and "pose hips@key 1" in done.stdout
    assert load_curves(out).curves.times.size == 5  # the four key poses and the seam
    env = dict(os.environ, SDL_VIDEODRIVER="dummy", SDL_AUDIODRIVER="dummy")
    replay = subprocess.run([sys.executable, "-m", "puppetphone", "replay", str(rec), "--verify", "--headless"],
                            capture_output=True, text=True, env=env, cwd=tmp_path, timeout=300)  # fmt: skip
    assert replay.returncode == 0, replay.stdout + replay.stderr
    assert "replayed 120 frames, all 120 state hashes match" in replay.stdout
