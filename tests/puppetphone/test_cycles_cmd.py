"""``puppetphone cycles``: a library from a folder, a second run that does nothing, a killed run resumed.

Every test runs the command as a user types it (a subprocess), on synthetic takes made by
the bench's generator (:func:`bench.cycles_batch.write_takes`) or on the real mocap folder.
"""

from __future__ import annotations

import os
import re
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import pytest

from authoring.batch.index import read_index
from puppetphone.bench.cycles_batch import write_takes

CLI = [sys.executable, "-m", "puppetphone", "cycles"]
SUMMARY = re.compile(
    r"^cycles: (\d+) looped \((\d+) clips\), (\d+) refused, (\d+) failed, (\d+) already done, in [\d.]+ s"
)


def _cycles(*args: str, timeout: float = 300) -> subprocess.CompletedProcess[str]:
    return subprocess.run([*CLI, *args], check=False, capture_output=True, text=True, timeout=timeout)


def _content(lib: Path) -> tuple[list[tuple], list[tuple]]:
    """The index without the time spent per take (the only field a rerun may change)."""
    takes, clips = read_index(lib)
    for c in clips:
        import hashlib

        assert hashlib.sha256(c.path.read_bytes()).hexdigest() == c.sha256, c.file
    return [(t.hash, t.source, t.outcome, t.reason, t.frames, t.dims, t.clips) for t in takes], [
        tuple(vars(c)[k] for k in vars(c) if k != "path") for c in clips
    ]


def test_real_mocap_folder_then_nothing_to_do(mocap_dir: Path, tmp_path: Path) -> None:
    lib = tmp_path / "lib"
    first = _cycles(str(mocap_dir), "-o", str(lib), "--jobs", "2")
    assert first.returncode == 0, first.stderr
    m = SUMMARY.match(first.stdout.strip().splitlines()[-1])
    assert m, first.stdout
    looped, clips, refused, failed = (int(m[i]) for i in range(1, 5))
    from authoring.cycles.formats import INPUT_SUFFIXES

    takes_in = len([f for f in mocap_dir.iterdir() if f.suffix.lower() in INPUT_SUFFIXES])  # BVH, glTF and GLB
    assert looped + refused == takes_in and failed == 0 and clips >= looped >= 5
    takes, entries = read_index(lib)
    assert len(takes) == takes_in and len(entries) == clips
    assert any(c.source.endswith("Fox.glb") for c in entries)  # a skinned GLB's walk loops too
    jump = next(t for t in takes if "forward_jump_NEGATIVE" in t.source)
    assert jump.outcome == "refused" and jump.reason
    walk = next(c for c in entries if "cmu_16_15_walk" in c.source)
    assert walk.kind == "walk" and walk.period == pytest.approx(1.17, rel=0.03) and 0.7 < walk.speed < 1.6
    assert walk.licence.startswith("CMU") and next(c for c in entries if "bandai" in c.source).licence.startswith(
        "CC BY-NC"
    )
    from engine.clipfile import load_clip

    assert load_clip(walk.path).loop
    per_take = [line for line in first.stdout.splitlines() if line.startswith(("looped ", "refused ", "failed "))]
    assert len({line.split()[1].rstrip(":") for line in per_take}) == takes_in
    second = _cycles(str(mocap_dir), "-o", str(lib))
    assert second.returncode == 0
    assert second.stdout.strip() == f"cycles: nothing to do: {takes_in} take(s) already in {lib / 'index.sqlite'}"


def test_killed_run_resumes_to_the_same_index(tmp_path: Path) -> None:
    write_takes(tmp_path / "takes", count=16)
    reference = _cycles(str(tmp_path / "takes"), "-o", str(tmp_path / "ref"), "--jobs", "2")
    assert reference.returncode == 0, reference.stderr
    lib = tmp_path / "lib"
    proc = subprocess.Popen(
        [*CLI, str(tmp_path / "takes"), "-o", str(lib), "--jobs", "1"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )
    done = 0
    deadline = time.monotonic() + 240
    while time.monotonic() < deadline and proc.poll() is None:
        time.sleep(0.2)
        try:
            con = sqlite3.connect(f"file:{lib / 'index.sqlite'}?mode=ro", uri=True)
            done = con.execute("SELECT COUNT(*) FROM takes").fetchone()[0]
            con.close()
        except sqlite3.Error:
            continue
        if done >= 4:
            break
    assert proc.poll() is None, "the run ended before it could be killed"
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    partial = len(read_index(lib)[0])
    assert 4 <= partial < 16
    resumed = _cycles(str(tmp_path / "takes"), "-o", str(lib), "--jobs", "2")
    assert resumed.returncode == 0, resumed.stderr
    m = SUMMARY.match(resumed.stdout.strip().splitlines()[-1])
    assert m and int(m[5]) == partial and int(m[1]) + int(m[3]) == 16 - partial
    assert _content(lib) == _content(tmp_path / "ref")


def test_bad_file_is_reported_and_the_batch_goes_on(tmp_path: Path) -> None:
    write_takes(tmp_path / "takes", count=3)
    (tmp_path / "takes" / "broken.bvh").write_text("HIERARCHY\nROOT Hips\n{\n")
    (tmp_path / "takes" / "empty.csv").write_text("")
    r = _cycles(str(tmp_path / "takes"), "-o", str(tmp_path / "lib"), "--jobs", "1")
    assert r.returncode == 3 and "Traceback" not in r.stderr  # done, some takes unreadable (1: the run failed)
    lines = r.stdout.splitlines()
    assert any(line.startswith("failed   broken.bvh: cannot read: line ") for line in lines)
    assert any(line.startswith("failed   empty.csv: cannot read") for line in lines)
    assert all(line.count("broken.bvh") <= 1 and line.count("empty.csv") <= 1 for line in lines)  # the file named once
    m = SUMMARY.match(lines[-1])
    assert m and int(m[1]) == 3 and int(m[4]) == 2
    # A rerun leaves the failed takes alone; --retry-failed reads them again (as after a reader fix).
    again = _cycles(str(tmp_path / "takes"), "-o", str(tmp_path / "lib"), "--jobs", "1")
    assert again.returncode == 0 and "nothing to do" in again.stdout
    retry = _cycles(str(tmp_path / "takes"), "-o", str(tmp_path / "lib"), "--jobs", "1", "--retry-failed")
    m = SUMMARY.match(retry.stdout.splitlines()[-1])
    assert retry.returncode == 3 and m and int(m[4]) == 2 and int(m[5]) == 3


def test_bad_arguments_in_one_line(tmp_path: Path) -> None:
    write_takes(tmp_path / "takes", count=1)
    r = _cycles(str(tmp_path / "nothing*.bvh"), "-o", str(tmp_path / "lib"))
    assert r.returncode == 2 and r.stderr.strip().count("\n") == 0 and "no such file" in r.stderr
    assert _cycles(str(tmp_path / "takes"), "-o", str(tmp_path / "lib"), "--jobs", "1").returncode == 0
    other = _cycles(str(tmp_path / "takes"), "-o", str(tmp_path / "lib"), "--no-segments")
    assert other.returncode == 2 and "was built with" in other.stderr
    (tmp_path / "file").write_text("x")
    assert _cycles(str(tmp_path / "takes"), "-o", str(tmp_path / "file")).returncode == 2


def test_dask_local_cluster_of_two_workers(tmp_path: Path) -> None:
    """The cluster listens on free ports only: with ``dashboard_address=None`` the scheduler's HTTP server
    still took 8787, and the test failed whenever that was in use (shown by holding 8787 while it ran)."""
    distributed = pytest.importorskip("distributed", reason="Dask's distributed is not installed (the 'cluster' extra)")
    write_takes(tmp_path / "takes", count=8)
    # A scheduler nobody listens on: the command retries for its 20 s connect timeout before it gives up,
    # a wait of nearly no CPU. Started first, it waits while the runs below work, instead of after them.
    unreachable = subprocess.Popen(
        [*CLI, str(tmp_path / "takes"), "-o", str(tmp_path / "x"), "--scheduler", "tcp://127.0.0.1:9"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    local = _cycles(str(tmp_path / "takes"), "-o", str(tmp_path / "local"), "--jobs", "1")
    assert local.returncode == 0, local.stderr
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address="127.0.0.1:0"
    ) as cluster:  # any free port, not 8787
        for mode in ([], ["--send-bytes"]):
            lib = tmp_path / f"dask{len(mode)}"
            r = _cycles(str(tmp_path / "takes"), "-o", str(lib), "--scheduler", cluster.scheduler_address, *mode)
            assert r.returncode == 0, r.stderr
            assert SUMMARY.match(r.stdout.strip().splitlines()[-1])
            assert _content(lib) == _content(tmp_path / "local")
    _, unreachable_err = unreachable.communicate(timeout=300)
    assert unreachable.returncode == 2 and "cannot reach the Dask scheduler" in unreachable_err


def test_retarget_puppet_writes_clips_on_the_puppet_skeleton(mocap_dir: Path, tmp_path: Path) -> None:
    from engine.clipfile import load_clip
    from engine.humanoid import humanoid_skeleton

    r = _cycles(
        str(mocap_dir / "cmu_16_15_walk_daz.bvh"),
        str(mocap_dir / "bandai1_walk_normal_001.bvh"),
        "-o",
        str(tmp_path / "lib"),
        "--retarget",
        "puppet",
        "--jobs",
        "1",
    )
    assert r.returncode == 0, r.stderr
    _, clips = read_index(tmp_path / "lib")
    assert len(clips) == 2
    for c in clips:
        clip = load_clip(c.path)
        assert clip.skeleton.names == humanoid_skeleton().names and clip.loop
        assert clip.duration == pytest.approx(c.period, rel=0.02)
