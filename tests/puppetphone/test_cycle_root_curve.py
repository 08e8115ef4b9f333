"""``cycle -o x.ppclip`` carries the extractor's root curve; MoCurves open exactly its control points."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from authoring.cycles.extract import extract_cycle
from authoring.cycles.formats import load_performance, loop_clip
from authoring.cycles.root_curve import loop_root_curve
from authoring.mocurves import EditSession, load_session, save_session
from engine import quat
from engine.clip import Clip
from engine.clipfile import ClipFileError, load_clip_curve
from engine.humanoid import humanoid_skeleton
from engine.io import clip_to_bvh, write_bvh
from engine.root_curve import RootCurve


def _straight_walk_bvh(path: Path, frames: int = 600, fps: float = 60.0) -> Path:
    """Nine strides along +Z, heading held (so the world root is the extractor's body-frame curve)."""
    sk = humanoid_skeleton()
    t = np.arange(frames) / fps
    ph = 2 * np.pi * t
    root = np.stack([0.03 * np.sin(ph), 0.9 + 0.02 * np.cos(2 * ph), 1.2 * t], axis=1)
    root += np.random.default_rng(0).normal(scale=0.0005, size=root.shape)
    rot = quat.identity(frames, sk.num_joints)
    for j in range(1, sk.num_joints):
        rot[:, j] = quat.from_axis_angle([1.0, 0.0, 0.0] if j % 2 else [0.0, 0.0, 1.0], 0.3 * np.sin(ph + j))
    return write_bvh(path, clip_to_bvh(Clip("walk", sk, fps, root, rot)))


def _cycle(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    exe = Path(sys.executable).with_name("puppetphone")
    return subprocess.run(
        [str(exe), "cycle", *args],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "PYTHONHASHSEED": "0"},
    )


def test_cycle_clip_opens_with_the_extractors_control_points(tmp_path: Path) -> None:
    bvh = _straight_walk_bvh(tmp_path / "walk.bvh")
    done = _cycle(str(bvh), "-o", "walk.ppclip", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    # What the extractor fitted, in this process, on the same file.
    perf = load_performance(bvh, None)
    result = extract_cycle(perf.trajectory, np.random.default_rng(0))
    world = loop_clip(result, perf)
    curve = loop_root_curve(result, perf, world)
    fitted = result.curves[f"{perf.clip.skeleton.names[0]}.position"]
    assert curve is not None and curve.count == fitted.segments
    # The loop is stored in place (its travel is root motion): the curve loses the same ramp and start.
    start = world.root[0] * [1.0, 0.0, 1.0]
    expected = RootCurve(curve.control - start, curve.travel * [0.0, 1.0, 0.0])

    session = load_session(tmp_path / "walk.ppclip")
    root = session.clip.skeleton.names[0]
    assert session.root_curve is not None and session.clip.root_motion is not None
    assert np.allclose(session.root_curve.control, expected.control, atol=1e-12)
    assert np.allclose(session.root_curve.travel, expected.travel, atol=1e-12)
    assert session.clip.average_speed() == pytest.approx(np.linalg.norm(curve.travel) / world.duration, rel=1e-9)
    assert session.control_count(root) == fitted.segments != EditSession(session.clip).control_count(root)
    assert np.allclose(session.control_points(root), expected.shown(), atol=1e-12)
    # The curve is the clip's root within the extractor's bound.
    assert np.abs(expected.positions(session.clip.num_frames) - session.clip.root).max() <= 2 * max(
        fitted.max_error, 1e-3
    )
    # Other items still get MoCurves' own fit.
    assert session.control_count("l_hand") == max(4, session.clip.num_frames // 5)


def test_edited_clip_round_trips_with_its_curve(tmp_path: Path) -> None:
    bvh = _straight_walk_bvh(tmp_path / "walk.bvh")
    assert _cycle(str(bvh), "-o", "walk.ppclip", cwd=tmp_path).returncode == 0
    session = load_session(tmp_path / "walk.ppclip")
    root = session.clip.skeleton.names[0]
    before = session.root_curve
    assert before is not None
    residual = session.clip.root - before.positions(session.clip.num_frames)
    session.move_control_point(root, 2, [0.0, 0.05, 0.0])
    after = session.root_curve
    assert after is not None and np.array_equal(after.control[2], before.control[2] + [0.0, 0.05, 0.0])
    # The drag moved the keypoints exactly as the curve moved; the residual detail rode along.
    assert np.allclose(session.clip.root - after.positions(session.clip.num_frames), residual, atol=1e-12)
    session.retime(root, {5: 7 / session.clip.fps})  # moves the root another way: the curve is re-fitted to it
    assert not np.array_equal(session.root_curve.control, after.control)
    assert np.array_equal(session.root_curve.control, after.refit(session.clip.root).control)
    assert session.control_count(root) == after.count
    save_session(session, tmp_path / "edited.ppclip")
    reopened = load_session(tmp_path / "edited.ppclip")
    assert reopened.root_curve is not None
    assert np.array_equal(reopened.root_curve.control, session.root_curve.control)
    assert np.array_equal(reopened.clip.root, session.clip.root)
    assert session.undo() and session.undo() and session.root_curve is before


def test_corrupt_curve_section_is_refused_by_author_edit(tmp_path: Path) -> None:
    bvh = _straight_walk_bvh(tmp_path / "walk.bvh")
    assert _cycle(str(bvh), "-o", "walk.ppclip", cwd=tmp_path).returncode == 0
    from tests.engine.test_clip import _rewrite_signed

    _rewrite_signed(tmp_path / "walk.ppclip", lambda h, a: a.update(root_curve_control=a["root_curve_control"][:3]))
    with pytest.raises(ClipFileError, match="root curve has shapes"):
        load_clip_curve(tmp_path / "walk.ppclip")
    exe = Path(sys.executable).with_name("puppetphone")
    done = subprocess.run(
        [str(exe), "author", "edit", "walk.ppclip", "--headless", "--frames", "1"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "SDL_VIDEODRIVER": "dummy"},
    )
    assert done.returncode != 0 and "root curve has shapes" in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1


def test_swaying_walk_keeps_mocurves_own_fit(tmp_path: Path, mocap_dir: Path) -> None:
    """CMU 16_15: the heading sways 7° per stride, the world root is not the body-frame curve: none is stored."""
    done = _cycle(str(mocap_dir / "cmu_16_15_walk_daz.bvh"), "-o", "walk.ppclip", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    clip, curve = load_clip_curve(tmp_path / "walk.ppclip")
    assert (
        curve is None
        and load_session(tmp_path / "walk.ppclip").control_count(clip.skeleton.names[0]) == clip.num_frames // 5
    )


def test_a_retargeted_loop_plays_in_place_with_its_travel_as_root_motion(tmp_path: Path) -> None:
    """``cycle --retarget puppet -o walk.ppclip`` opens over the origin, without a stride-long jump at the seam."""
    from puppetphone.cli import main
    from tests.engine.io.synthetic_bvh import human_bvh

    (tmp_path / "take.bvh").write_text(human_bvh(frames=300, fps=60.0, period=1.0, turn=6.0, turn_period=2.0))
    assert main(["cycle", str(tmp_path / "take.bvh"), "--retarget", "puppet", "-o", str(tmp_path / "walk.ppclip")]) == 0
    session = load_session(tmp_path / "walk.ppclip")
    clip = session.clip
    assert clip.root_motion is not None and clip.average_speed() > 0.5
    steps = np.linalg.norm(np.diff(clip.root[:, [0, 2]], axis=0), axis=1)
    seam = float(np.linalg.norm((clip.root[0] - clip.root[-1])[[0, 2]]))
    assert seam <= 2.0 * steps.max() and np.abs(clip.root[:, [0, 2]]).max() < 0.2
    assert session.curves()[clip.skeleton.names[0]].speeds().max() < 3.0  # was ~150 m/s: the seam's jump back
