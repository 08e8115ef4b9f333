"""Performances in and loops out: CSV, npz, BVH, clips and recordings."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from authoring.cycles.extract import extract_cycle
from authoring.cycles.formats import load_performance, loop_clip, loop_travel, save_loop
from authoring.cycles.synthetic import make_performance
from authoring.cycles.trajectory import TrajectoryError
from engine import quat


def _write_csv(path: Path, t: np.ndarray, v: np.ndarray, names: list[str]) -> None:
    lines = [",".join(["time", *names])] + [
        ",".join(repr(float(x)) for x in [ti, *row]) for ti, row in zip(t, v, strict=True)
    ]
    path.write_text("\n".join(lines) + "\n")


def test_csv_round_trip_with_named_items(tmp_path: Path) -> None:
    perf = make_performance(3, np.random.default_rng(0), cycles=6, rotations=1)
    tr = perf.trajectory
    names = ["hand.x", "hand.y", "hand.z", "head.qw", "head.qx", "head.qy", "head.qz"]
    _write_csv(tmp_path / "in.csv", tr.times, tr.values, names)
    loaded = load_performance(tmp_path / "in.csv")
    assert [(it.name, it.kind) for it in loaded.trajectory.items] == [("hand", "position"), ("head", "rotation")]
    assert np.allclose(loaded.trajectory.values, tr.values)
    r = extract_cycle(loaded.trajectory)
    save_loop(r, loaded, tmp_path / "out.csv")
    back = load_performance(tmp_path / "out.csv")
    assert np.allclose(back.trajectory.values, r.loop)
    assert np.allclose(back.trajectory.times, r.loop_times)
    assert abs(r.period / perf.period - 1) < 0.02


def test_items_select_columns(tmp_path: Path) -> None:
    t = np.arange(100) / 30
    _write_csv(tmp_path / "a.csv", t, np.stack([t, t * 2, t * 3], axis=1), ["a", "b", "c"])
    perf = load_performance(tmp_path / "a.csv", ["c", "a"])
    assert perf.names == ("a", "c")
    assert np.allclose(perf.trajectory.values[:, 1], t * 3)
    with pytest.raises(TrajectoryError, match="no item 'z'"):
        load_performance(tmp_path / "a.csv", ["z"])


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("t,a\n0,1\n1,2\n", "first column must be 'time'"),
        ("time,a\n0,1\n1,x\n", "non-numeric"),
        ("time,a\n", "header row and data rows"),
        ("time,a\n0,1\n0,2\n1,3\n", "increase strictly"),
    ],
)
def test_bad_csv_is_refused(tmp_path: Path, text: str, message: str) -> None:
    (tmp_path / "bad.csv").write_text(text)
    with pytest.raises(TrajectoryError, match=message):
        load_performance(tmp_path / "bad.csv")


def test_npz_round_trip(tmp_path: Path) -> None:
    perf = make_performance(5, np.random.default_rng(1), cycles=6)
    np.savez(tmp_path / "in.npz", values=perf.trajectory.values, fps=60.0)
    loaded = load_performance(tmp_path / "in.npz")
    r = extract_cycle(loaded.trajectory)
    save_loop(r, loaded, tmp_path / "out.npz")
    with np.load(tmp_path / "out.npz") as z:
        assert np.allclose(z["values"], r.loop)
        assert float(z["period"]) == pytest.approx(r.period)
    np.savez(tmp_path / "bad.npz", other=np.zeros(3))
    with pytest.raises(TrajectoryError, match="'values'"):
        load_performance(tmp_path / "bad.npz")


def test_unknown_types_are_refused(tmp_path: Path) -> None:
    (tmp_path / "x.txt").write_text("1")
    with pytest.raises(TrajectoryError, match="unknown input type"):
        load_performance(tmp_path / "x.txt")
    with pytest.raises(FileNotFoundError):
        load_performance(tmp_path / "missing.csv")


def test_generic_input_cannot_become_a_clip(tmp_path: Path) -> None:
    perf = make_performance(2, np.random.default_rng(1), cycles=6)
    np.savez(tmp_path / "in.npz", values=perf.trajectory.values, times=perf.trajectory.times)
    loaded = load_performance(tmp_path / "in.npz")
    r = extract_cycle(loaded.trajectory)
    with pytest.raises(TrajectoryError, match="skeletal"):
        save_loop(r, loaded, tmp_path / "out.ppclip")
    assert not (tmp_path / "out.ppclip").exists()


def test_bvh_to_clip_and_bvh(tmp_path: Path, mocap_dir: Path) -> None:
    from engine.clipfile import load_clip
    from engine.io.bvh import read_bvh

    perf = load_performance(mocap_dir / "bandai1_walk_normal_001.bvh")
    r = extract_cycle(perf.trajectory)
    clip = loop_clip(r, perf)
    assert clip.loop and clip.skeleton == perf.clip.skeleton  # type: ignore[union-attr]
    assert clip.duration == pytest.approx(r.period)
    save_loop(r, perf, tmp_path / "walk.ppclip")
    back = load_clip(tmp_path / "walk.ppclip")
    assert back.loop and back.num_frames == len(r.loop)
    assert np.allclose(np.abs(np.sum(back.rotations * clip.rotations, axis=-1)), 1.0, atol=1e-9)
    # The loop joins itself: the step from the last frame to the first is like any other step.
    steps = quat.angle_between(back.rotations[1:], back.rotations[:-1]).max(axis=1)
    wrap = quat.angle_between(back.rotations[0], back.rotations[-1]).max()
    assert wrap <= 2.0 * steps.max()
    # BVH loops land at the source's nominal rate (30 fps) on a whole number of frames, closed.
    save_loop(r, perf, tmp_path / "walk.bvh")
    bvh = read_bvh(tmp_path / "walk.bvh")
    whole = round(r.period * 30)
    assert bvh.frame_time == 1 / 30 and bvh.num_frames == whole + 1
    assert np.allclose(bvh.data[-1, 3:], bvh.data[0, 3:], atol=1e-6)  # the closing frame repeats the pose
    # 32.5 frames became 33: the travel stretched with the loop, so it walks at the loop's speed.
    speed = np.linalg.norm((bvh.data[-1, :3] - bvh.data[0, :3])[[0, 2]]) / 100.0 / (whole * bvh.frame_time)
    assert speed == pytest.approx(np.linalg.norm(loop_travel(r, perf)[0][[0, 2]]) / r.period, rel=1e-3)
    save_loop(r, perf, tmp_path / "open.bvh", fps=24.0, closing_frame=False)
    bvh = read_bvh(tmp_path / "open.bvh")
    assert bvh.frame_time == 1 / 24 and bvh.num_frames == round(r.period * 24)


def test_selected_joints_only(mocap_dir: Path) -> None:
    perf = load_performance(mocap_dir / "bandai1_walk_normal_001.bvh", ["Hips", "UpperLeg_L", "UpperLeg_R"])
    assert perf.trajectory.dims == 3 + 3 * 4 + 1  # root position, three rotations, the heading
    r = extract_cycle(perf.trajectory)
    assert 30 <= r.period_samples <= 35


def test_recording_input(tmp_path: Path) -> None:
    """A mouse performance recorded by the engine's recorder: the pivot and orientation are the trajectory."""
    from input.recording import Recorder, RecordingHeader
    from input.sample import InputFrame, PoseSample

    perf = make_performance(3, np.random.default_rng(4), cycles=6, fps=60.0, noise=0.01)
    pos = perf.trajectory.values
    yaw = 0.3 * pos[:, 0]
    ori = quat.from_axis_angle(np.array([0.0, 1.0, 0.0]), yaw)
    with Recorder(tmp_path / "take.rec", RecordingHeader(game="author", seed=0, dt=1 / 60)) as rec:
        for i in range(len(pos)):
            sample = PoseSample(time=i / 60, source="mouse", orientation=ori[i], position=pos[i], mode="world")
            rec.write(InputFrame(frame=i, samples=(sample,)), "00" * 16)
    loaded = load_performance(tmp_path / "take.rec")
    kinds = [(it.name, it.kind) for it in loaded.trajectory.items]
    assert kinds == [("mouse.position", "position"), ("mouse.orientation", "rotation")]
    r = extract_cycle(loaded.trajectory)
    assert abs(r.period / perf.period - 1) < 0.02
    with pytest.raises(TrajectoryError, match="no source 'phone'"):
        load_performance(tmp_path / "take.rec", ["phone"])


def test_npz_that_is_damaged_hostile_or_absurd_is_a_trajectory_error(tmp_path: Path) -> None:
    import io
    import zipfile

    t = np.arange(50) / 30.0
    v = np.sin(t)[:, None]
    cases = {}
    cases["garbage"] = b"PK\x03\x04 not really a zip"
    buf = io.BytesIO()
    np.savez(buf, values=v, times=t)
    good = buf.getvalue()
    cases["cut"] = good[: len(good) // 2]
    buf = io.BytesIO()
    np.savez(buf, values=np.array(["a", "b"]), fps=np.float64(30))
    cases["strings"] = buf.getvalue()
    buf = io.BytesIO()
    np.savez(buf, values=v * 1e300, times=t)
    cases["huge"] = buf.getvalue()
    buf = io.BytesIO()
    np.savez(buf, values=v, fps=np.float64(np.nan))
    cases["nan fps"] = buf.getvalue()
    head = io.BytesIO()
    np.lib.format.write_array_header_1_0(head, {"descr": "<f8", "fortran_order": False, "shape": (10**10, 8)})
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as z:
        z.writestr("values.npy", head.getvalue() + bytes(80))
        z.writestr("fps.npy", b"")
    cases["claims 640 GB"] = buf.getvalue()
    buf = io.BytesIO()
    np.savez(buf, values=np.array([object()], dtype=object), fps=np.float64(30))
    cases["objects"] = buf.getvalue()
    for name, data in cases.items():
        path = tmp_path / "p.npz"
        path.write_bytes(data)
        with pytest.raises(TrajectoryError):
            load_performance(path)
            pytest.fail(name)


def test_finite_but_absurd_csv_values_are_refused(tmp_path: Path) -> None:
    t = np.arange(40) / 30.0
    _write_csv(tmp_path / "in.csv", t, np.column_stack([np.sin(t), np.full(40, 5e307)]), ["a", "b"])
    with pytest.raises(TrajectoryError, match="within"):
        load_performance(tmp_path / "in.csv")
