"""``puppetphone cycle``: the command-line contract (JSON last line, exit codes, outputs, plot)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from authoring.cycles.synthetic import make_performance
from puppetphone.cli import main


def _csv(path: Path, dims: int = 3, seed: int = 0) -> float:
    perf = make_performance(dims, np.random.default_rng(seed), cycles=6)
    tr = perf.trajectory
    names = [f"c{i}" for i in range(dims)]
    rows = [",".join(["time", *names])] + [
        ",".join(repr(float(x)) for x in [t, *v]) for t, v in zip(tr.times, tr.values, strict=True)
    ]
    path.write_text("\n".join(rows) + "\n")
    return perf.period


def _last_json(out: str) -> dict:
    return json.loads(out.strip().splitlines()[-1])


def test_csv_to_csv_with_json_and_plot(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    period = _csv(tmp_path / "take.csv")
    code = main(
        [
            "cycle",
            str(tmp_path / "take.csv"),
            "-o",
            str(tmp_path / "loop.csv"),
            "--json",
            "--plot",
            str(tmp_path / "fig.png"),
        ]
    )
    assert code == 0
    summary = _last_json(capsys.readouterr().out)
    assert {"period_frames", "period_seconds", "cycles", "dims", "closure_error", "seconds"} <= set(summary)
    assert abs(summary["period_seconds"] / period - 1) < 0.02
    assert summary["period_frames"] == pytest.approx(summary["period_seconds"] * 60, rel=1e-3)
    assert summary["dims"] == 3 and summary["cycles"] >= 4 and summary["closure_error"] < 1e-9
    lines = (tmp_path / "loop.csv").read_text().splitlines()
    assert lines[0] == "time,c0,c1,c2" and len(lines) - 1 == round(summary["period_frames"])
    png = (tmp_path / "fig.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 10_000


def test_no_cycle_exits_non_zero_with_reason(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    t = np.arange(300) / 60
    v = np.cumsum(np.random.default_rng(3).normal(size=(300, 2)), axis=0)
    rows = ["time,a,b"] + [f"{float(ti)!r},{float(a)!r},{float(b)!r}" for ti, (a, b) in zip(t, v, strict=True)]
    (tmp_path / "walk.csv").write_text("\n".join(rows))
    code = main(["cycle", str(tmp_path / "walk.csv"), "-o", str(tmp_path / "o.csv"), "--json"])
    captured = capsys.readouterr()
    assert code == 3
    assert "error" in _last_json(captured.out)
    assert "cycle:" in captured.err
    assert not (tmp_path / "o.csv").exists()


def test_bad_input_and_output(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["cycle", str(tmp_path / "none.csv"), "-o", str(tmp_path / "o.csv")]) == 2
    _csv(tmp_path / "take.csv")
    assert main(["cycle", str(tmp_path / "take.csv"), "-o", str(tmp_path / "o.xyz")]) == 2
    assert main(["cycle", str(tmp_path / "take.csv"), "-o", str(tmp_path / "o.ppclip")]) == 2
    err = capsys.readouterr().err
    assert "no such file" in err and "unknown output type" in err and "skeletal" in err


def test_bvh_walk_to_clip(tmp_path: Path, mocap_dir: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from engine.clipfile import load_clip

    out = tmp_path / "walk.ppclip"
    assert main(["cycle", str(mocap_dir / "cmu_16_15_walk_daz.bvh"), "-o", str(out), "--json"]) == 0
    summary = _last_json(capsys.readouterr().out)
    assert 136 <= summary["period_frames"] <= 144  # README: ≈140 frames at 120 fps
    assert summary["skipped_frames"] >= 1  # the T-pose lead-in
    given = summary["input"]  # counts as analysed and as in the file
    assert (
        given["file_frames"] == 472 and given["frames"] == 472 - given["skipped_frames"] and given["file_joints"] == 43
    )
    clip = load_clip(out)
    assert clip.loop and clip.duration == pytest.approx(summary["period_seconds"], rel=1e-6)


def test_a_one_cycle_gltf_loop_reports_one_cycle(
    tmp_path: Path, mocap_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert (
        main(["cycle", str(mocap_dir / "Fox.glb"), "--animation", "Walk", "-o", str(tmp_path / "w.glb"), "--json"]) == 0
    )
    summary = _last_json(capsys.readouterr().out)
    assert summary["cycles"] == 1 and summary["input"]["file_joints"] == 24


def test_jump_is_refused(tmp_path: Path, mocap_dir: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code = main(
        ["cycle", str(mocap_dir / "cmu_13_32_forward_jump_NEGATIVE_daz.bvh"), "-o", str(tmp_path / "j.bvh"), "--json"]
    )
    assert code == 3
    assert "period" in _last_json(capsys.readouterr().out)["error"]


def test_console_entry_point(tmp_path: Path) -> None:
    """The real process: ``python -m puppetphone cycle`` prints the JSON as its last stdout line."""
    _csv(tmp_path / "take.csv", dims=2, seed=4)
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "puppetphone",
            "cycle",
            str(tmp_path / "take.csv"),
            "-o",
            str(tmp_path / "l.npz"),
            "--json",
        ],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr
    assert _last_json(proc.stdout)["cycles"] >= 4
    assert (tmp_path / "l.npz").is_file()


@pytest.mark.parametrize("frames", [0, 1, 2, 3])
@pytest.mark.parametrize("kind", ["bvh", "npz"])
def test_too_few_frames_is_one_line_not_a_traceback(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], kind: str, frames: int
) -> None:
    from tests.engine.io.synthetic_bvh import human_bvh

    if kind == "bvh":
        src = tmp_path / "short.bvh"
        src.write_text(human_bvh(frames=frames))
    else:
        src = tmp_path / "short.npz"
        np.savez(src, times=np.arange(frames) / 30.0, values=np.ones((frames, 3)))
    assert main(["cycle", str(src), "-o", str(tmp_path / "out.npz")]) == 2
    err = capsys.readouterr().err
    assert "frame" in err and len(err.strip().splitlines()) == 1


def test_a_deeply_nested_joint_map_is_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from tests.engine.io.synthetic_bvh import human_bvh

    src, jm = tmp_path / "walk.bvh", tmp_path / "map.json"
    src.write_text(human_bvh())
    jm.write_text('{"a": ' + "[" * 100_000 + "]" * 100_000 + "}")
    assert main(["cycle", str(src), "--joint-map", str(jm), "-o", str(tmp_path / "out.ppclip")]) == 2
    assert "nested too deeply" in capsys.readouterr().err


def test_a_blender_bvh_is_stood_up_and_says_so(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from engine.io.bvh import read_bvh
    from tests.engine.io.synthetic_bvh import blender_bvh, walk_take

    blender_bvh(tmp_path / "blender.bvh", walk_take(4))
    assert main(["cycle", str(tmp_path / "blender.bvh"), "-o", str(tmp_path / "loop.bvh"), "--json"]) == 0
    given = _last_json(capsys.readouterr().out)["input"]
    assert given["up"] == "z" and "along z" in given["up_basis"] and 1.5 < given["height"] < 1.9
    loop = read_bvh(tmp_path / "loop.bvh")
    assert loop.column(0, "Yposition").min() > 70.0  # the loop written stands: hips ~0.9 m up, in cm
    assert main(["cycle", str(tmp_path / "blender.bvh"), "-o", str(tmp_path / "l.bvh"), "--json", "--up", "y"]) == 0
    assert _last_json(capsys.readouterr().out)["input"]["up_basis"] == "given"
