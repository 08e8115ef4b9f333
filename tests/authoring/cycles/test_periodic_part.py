"""Where a long take repeats only in part (issue 31, item 9): the salsa's steps, and no hint where nothing repeats.

The salsa (CMU 60_04, shared mocap) is refused as a whole and no part of it repeats in the
whole pose (the dancer turns, the arms vary); its feet keep a 1.46 s basic step (175 header
frames, the data README's figure) and keep it closely for a few seconds. The refusal names
that part and the legs, and following the hint gives a loop.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

from authoring.cycles.formats import load_performance
from authoring.cycles.periodic_part import leg_joints, steps_part
from authoring.cycles.take_range import refusal_hint

SALSA = "cmu_60_04_salsa_daz_scaled.bvh"


@pytest.fixture(scope="module")
def salsa(mocap_dir: Path):  # type: ignore[no-untyped-def]
    return load_performance(mocap_dir / SALSA)


@pytest.fixture(scope="module")
def mocap_dir() -> Path:  # module scope: the take is read once for every test here
    from tests.conftest import data_dir

    d = data_dir()
    if d is None:
        pytest.skip("real mocap data not found: set PUPPETPHONE_DATA or put shared/data beside the project")
    return d / "mocap"


def test_the_salsa_steps_repeat_closely_in_one_part(salsa) -> None:  # type: ignore[no-untyped-def]
    part = steps_part(salsa)
    assert part is not None
    assert part.period == pytest.approx(175 / 120, abs=0.03)  # the README's foot-height period
    dt = salsa.trajectory.dt
    seconds = (part.stop - part.start) * dt
    assert 3 * part.period <= seconds < 0.5 * salsa.trajectory.num_samples * dt  # a part, not the take
    assert part.correlation >= 0.7
    assert leg_joints(salsa) == ("hip", "lThigh", "lShin", "lFoot", "rThigh", "rShin", "rFoot")


def test_the_refused_salsa_names_where_its_steps_loop_and_the_hint_loops(
    salsa,
    mocap_dir: Path,  # type: ignore[no-untyped-def]
    tmp_path: Path,
) -> None:
    hint = refusal_hint(salsa, salsa)
    assert hint is not None
    m = re.search(
        r"frames (\d+)–(\d+) loop by the legs with period ([\d.]+) s \((\d+) cycles\); "
        r"try --start (\S+) --end (\S+) --items (.+)$",
        hint,
    )
    assert m, hint
    start, end, items = m.group(5), m.group(6), m.group(7).split()
    assert 8.0 <= float(start) < float(end) <= 15.0
    r = subprocess.run(
        [
            sys.executable,
            "-m",
            "puppetphone",
            "cycle",
            str(mocap_dir / SALSA),
            "-o",
            str(tmp_path / "steps.bvh"),
            "--start",
            start,
            "--end",
            end,
            "--items",
            *items,
            "--json",
        ],
        check=False,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 0, r.stderr
    summary = json.loads(r.stdout.strip().splitlines()[-1])
    assert summary["period_seconds"] == pytest.approx(float(m.group(3)), abs=0.01) and summary["cycles"] >= 3


def test_no_steps_and_no_hint_where_nothing_repeats(mocap_dir: Path) -> None:
    jump = load_performance(mocap_dir / "cmu_13_32_forward_jump_NEGATIVE_daz.bvh")
    assert steps_part(jump) is None and refusal_hint(jump, jump) is None
