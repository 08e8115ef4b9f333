"""Sizes of figures no unit fits, and of figures that are not people (issue 31, wall 6).

A hand alone is judged as a hand (0.19 m wrist to fingertip), never by a person's height; a
figure with no legs by its overall extent, and said so; any figure no unit makes a plausible
size is scaled continuously to a stated size, and ``--json``'s input block and the text
output say so. Files are generated here (:mod:`tests.engine.io.synthetic_bvh`) or are the
shared Khronos Fox.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from engine.io.bvh import write_bvh
from engine.io.bvh_convert import clip_to_bvh
from engine.io.motion_file import load_motion, scaled_clip
from engine.io.units import HUMAN_HAND, hand_length, rest_extent
from tests.engine.io.synthetic_bvh import hand_bvh, human_bvh


def _write(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def _cycle_json(path: Path, *options: str, code: int = 0) -> tuple[dict, str]:
    r = subprocess.run(
        [
            sys.executable,
            "-m",
            "puppetphone",
            "cycle",
            str(path),
            "-o",
            str(path.with_suffix(".loop.bvh")),
            "--json",
            *options,
        ],
        check=False,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == code, r.stderr
    return json.loads(r.stdout.strip().splitlines()[-1]).get("input", {}), r.stderr


@pytest.mark.parametrize(("unit", "name"), [(100.0, "cm"), (1000.0, "mm"), (1 / 0.0254, "in"), (1.0, "m")])
def test_a_hand_alone_is_judged_as_a_hand(tmp_path: Path, unit: float, name: str) -> None:
    motion = load_motion(_write(tmp_path, "hand.bvh", hand_bvh(unit=unit)), skip_tpose=False)
    assert motion.units.name == name and "fingers" in motion.units.basis
    assert hand_length(motion.clip.skeleton) == pytest.approx(HUMAN_HAND, rel=1e-3)


def test_a_hand_no_unit_fits_is_scaled_to_a_hand_and_says_so(tmp_path: Path) -> None:
    """0.57 file units from wrist to fingertip: a 0.57 m hand in metres, a 1.45 m one in inches; scaled instead."""
    path = _write(tmp_path, "hand.bvh", hand_bvh(unit=3.0))
    motion = load_motion(path, skip_tpose=False)
    assert motion.units.name == "scaled" and motion.units.scale == pytest.approx(1 / 3.0, rel=1e-6)
    assert hand_length(motion.clip.skeleton) == pytest.approx(HUMAN_HAND, rel=1e-3)
    given, stderr = _cycle_json(path)
    assert given["units"] == "scaled" and given["scaled_to"] == "a 0.19 m hand"
    assert given["unit_scale"] == pytest.approx(1 / 3.0, rel=1e-6)
    assert "note: hand.bvh: " in stderr and "scaled to a 0.19 m hand" in stderr and stderr.count("hand.bvh") == 1


def test_two_files_of_one_set_come_out_equally_tall(tmp_path: Path) -> None:
    """One figure in centimetres and rescaled by its uploader to a unit of its own, as the salsa was: equal heights."""
    cm, _ = _cycle_json(_write(tmp_path, "a.bvh", human_bvh(unit=100.0, frames=90)))
    odd, stderr = _cycle_json(_write(tmp_path, "b.bvh", human_bvh(unit=0.78, frames=90)))
    assert cm["units"] == "cm" and "scaled_to" not in cm
    assert odd["units"] == "scaled" and odd["scaled_to"] == "a 0.82 m leg" and "note: b.bvh" in stderr
    assert odd["height"] == pytest.approx(cm["height"], rel=1e-3)


def test_a_non_humanoid_is_judged_by_its_extent_never_its_legs(mocap_dir: Path, tmp_path: Path) -> None:
    fox = load_motion(mocap_dir / "Fox.glb", animation="Walk")
    assert fox.units.name == "cm" and fox.units.basis.startswith("no legs: figure extent")
    assert "leg" not in fox.units.basis.replace("no legs", "")
    # The same fox as a BVH in three sizes: centimetres and metres are read as such; 2 mm is no unit's fox.
    metres = scaled_clip(load_motion(mocap_dir / "Fox.glb", animation="Walk", units="cm").clip, 1.0)
    for unit, name in ((100.0, "cm"), (1.0, "m"), (0.0021, "scaled")):
        path = write_bvh(tmp_path / f"fox_{name}.bvh", clip_to_bvh(metres, unit=unit))
        motion = load_motion(path, skip_tpose=False)
        assert motion.units.name == name, motion.units
        assert motion.units.basis.startswith("no legs")
    assert motion.units.target == "a 1.7 m figure"
    assert rest_extent(motion.clip.skeleton) == pytest.approx(1.7, rel=1e-6)
    _, stderr = _cycle_json(tmp_path / "fox_cm.bvh", code=3)  # one stride is no take to loop; the note comes first
    assert "judged without legs" in stderr


def test_height_scales_to_a_stated_height_instead_of_a_unit(tmp_path: Path) -> None:
    path = _write(tmp_path, "w.bvh", human_bvh(unit=100.0, frames=90))
    given, _ = _cycle_json(path, "--height", "1.55")
    assert given["units"] == "scaled" and given["height"] == pytest.approx(1.55, abs=1e-4)
    assert given["scaled_to"] == "a 1.55 m tall figure"
    r = subprocess.run(
        [
            sys.executable,
            "-m",
            "puppetphone",
            "cycle",
            str(path),
            "-o",
            str(tmp_path / "x.bvh"),
            "--height",
            "1.5",
            "--units",
            "cm",
        ],
        check=False,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 2 and "give --units or --height, not both" in r.stderr


def test_a_library_run_says_how_it_sized_a_take_no_unit_fits(tmp_path: Path) -> None:
    """`cycles` names the scaling on the take's own line, as `cycle` does on stderr."""
    takes = tmp_path / "takes"
    takes.mkdir()
    _write(takes, "hand.bvh", hand_bvh(unit=3.0))
    env = {**os.environ, "SDL_VIDEODRIVER": "dummy"}
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "puppetphone",
            "cycles",
            str(takes),
            "-o",
            str(tmp_path / "lib"),
            "--jobs",
            "1",
            "--no-progress",
        ],
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode in (0, 3), done.stderr
    notes = [line for line in done.stdout.splitlines() if line.startswith("note")]
    assert len(notes) == 1 and "hand.bvh" in notes[0] and "scaled to a 0.19 m hand" in notes[0], done.stdout
