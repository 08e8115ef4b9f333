"""``puppetphone cycle --start/--end`` and the refusal that names the part that loops (issue 18, item 5).

The take is synthetic with three activities in a row (jumping jacks 1.0 s, twists 1.6 s,
squats 0.7 s): refused as a whole, and the jumping-jack part extracted with ``--start/--end``.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from authoring.cycles.synthetic import loop_error, mixed_take

CLI = [sys.executable, "-m", "puppetphone"]


def _write_csv(path: Path, seed: int = 0) -> tuple[list, np.ndarray]:
    take, parts, bounds = mixed_take(12, np.random.default_rng(seed))
    rows = [",".join(["time", *(f"c{i}" for i in range(take.dims))])]
    rows += [",".join(repr(float(x)) for x in [t, *v]) for t, v in zip(take.times, take.values, strict=True)]
    path.write_text("\n".join(rows) + "\n")
    return parts, bounds


def _cycle(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([*CLI, "cycle", *args], check=False, capture_output=True, text=True, timeout=120)


def test_refusal_names_the_best_segment_and_the_hint_extracts_the_jumping_jacks(tmp_path: Path) -> None:
    parts, bounds = _write_csv(tmp_path / "mixed.csv")
    out = tmp_path / "loop.npz"
    whole = _cycle(str(tmp_path / "mixed.csv"), "-o", str(out))
    assert whole.returncode == 3 and not out.exists()
    m = re.search(
        r"frames (\d+)–(\d+) loop with period ([\d.]+) s \((\d+) cycles\); try --start (\S+) --end (\S+)$",
        whole.stderr.strip(),
    )
    assert m, whole.stderr
    assert whole.stderr.count("\n") == 1  # one line
    f0, f1, period = int(m[1]), int(m[2]), float(m[3])
    assert abs(f0 / 60 - bounds[0]) < 0.5 and abs((f1 + 1) / 60 - bounds[1]) < 0.5  # the jumping jacks
    assert period == pytest.approx(parts[0].period, abs=0.02)
    hinted = _cycle(str(tmp_path / "mixed.csv"), "-o", str(out), "--start", m[5], "--end", m[6], "--json")
    assert hinted.returncode == 0, hinted.stderr
    assert json.loads(hinted.stdout.strip().splitlines()[-1])["period_seconds"] == pytest.approx(
        parts[0].period, rel=0.02
    )
    with np.load(out) as z:
        assert loop_error(z["values"], parts[0].truth)[0] < 0.1


@pytest.mark.parametrize("which", [0, 1, 2])
def test_start_end_in_seconds_or_frames_extracts_each_activity(tmp_path: Path, which: int) -> None:
    parts, bounds = _write_csv(tmp_path / "mixed.csv")
    out = tmp_path / "loop.npz"
    pad = 0.4  # a little inside the activity: the fades belong to neither
    if which == 1:  # frames
        start, end = f"{round((bounds[1] + pad) * 60)}f", f"{round((bounds[2] - pad) * 60)}f"
    else:
        start, end = f"{bounds[which] + pad:.2f}", f"{bounds[which + 1] - pad:.2f}s"
    r = _cycle(str(tmp_path / "mixed.csv"), "-o", str(out), "--start", start, "--end", end, "--json")
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout.strip().splitlines()[-1])["period_seconds"] == pytest.approx(
        parts[which].period, rel=0.03
    )
    with np.load(out) as z:
        assert loop_error(z["values"], parts[which].truth)[0] < 0.1


@pytest.mark.parametrize(
    ("start", "end", "message"),
    [
        ("3x", "5", "is not a time in seconds"),
        ("-1", "5", "from 0 on"),
        ("8", "4", "is not a range inside the take"),
        ("0", "99", "is not a range inside the take"),
    ],
)
def test_bad_ranges_are_refused_in_one_line(tmp_path: Path, start: str, end: str, message: str) -> None:
    _write_csv(tmp_path / "mixed.csv")
    r = _cycle(str(tmp_path / "mixed.csv"), "-o", str(tmp_path / "o.csv"), "--start", start, "--end", end)
    assert r.returncode == 2 and message in r.stderr and "Traceback" not in r.stderr
    assert not (tmp_path / "o.csv").exists()
