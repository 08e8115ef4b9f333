"""The one registry of motion-file formats (issue 34): every command's suffixes come from it, nowhere else.

Six suffix lists used to be kept by hand (``cycle``'s inputs and outputs, ``clips add``, the
MoCurves export, the loader, ``author edit``'s option check); they are now queries of
:data:`engine.io.formats.FORMATS`. The tests read the lists the commands use, round-trip
every clip format through the registry's own reader and writer, and scan the packages for
a suffix list written out anew.
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from authoring.cycles.formats import INPUT_SUFFIXES, OUTPUT_SUFFIXES
from authoring.mocurves.storage import EXPORT_SUFFIXES, export_clip
from engine.cliplib.source import SOURCE_SUFFIXES, read_source
from engine.clips import default_clips
from engine.io.formats import FORMATS, motion_format, suffixes
from engine.io.motion_file import MOTION_SUFFIXES, MotionFileError

ROOT = Path(__file__).resolve().parents[3]
PACKAGES = ("engine", "input", "authoring", "games", "puppetphone")


def test_each_suffix_names_one_format_in_any_case() -> None:
    seen = [s for f in FORMATS.values() for s in f.suffixes]
    assert len(seen) == len(set(seen))
    for name, fmt in FORMATS.items():
        for s in fmt.suffixes:
            assert motion_format(Path("take" + s.upper())) is fmt and fmt.name == name
    assert motion_format("take.txt") is None and motion_format("take") is None


def test_every_command_list_is_a_query_of_the_registry() -> None:
    assert MOTION_SUFFIXES == (".bvh", ".glb", ".gltf")  # files from other tools: units, up and animation judged
    assert SOURCE_SUFFIXES == EXPORT_SUFFIXES == (".bvh", ".glb", ".gltf", ".ppclip")
    assert INPUT_SUFFIXES == (".bvh", ".glb", ".gltf", ".csv", ".npz", ".rec")
    assert OUTPUT_SUFFIXES == (".bvh", ".glb", ".gltf", ".ppclip", ".csv", ".npz")
    assert set(SOURCE_SUFFIXES) == set(suffixes(skeletal=True))


@pytest.mark.parametrize("suffix", suffixes(skeletal=True, writable=True))
def test_every_clip_format_round_trips_through_its_reader_and_writer(tmp_path: Path, suffix: str) -> None:
    walk = default_clips()["walk"]
    path = export_clip(walk, tmp_path / f"walk{suffix}")
    clip, note = read_source(path)
    assert note is None and clip.loop
    assert clip.skeleton.names == walk.skeleton.names
    assert abs(clip.num_frames - walk.num_frames) <= 1
    speed = clip.average_speed() if clip.root_motion is not None else np.linalg.norm(clip.root_travel()) / clip.duration
    assert speed == pytest.approx(walk.average_speed(), rel=0.01)


def test_a_ppclip_refuses_options_meant_for_another_tools_file(tmp_path: Path) -> None:
    path = export_clip(default_clips()["walk"], tmp_path / "walk.ppclip")
    with pytest.raises(MotionFileError, match="--units only apply to a file from another tool"):
        read_source(path, units="cm")


def test_no_package_keeps_a_suffix_list_of_its_own() -> None:
    """A tuple or set of two or more motion suffixes written out outside the registry is a seventh list."""
    listed = re.compile(
        r"""[(\[{]\s*["']\.(bvh|glb|gltf|ppclip|csv|npz|rec)["']\s*,\s*["']\.(bvh|glb|gltf|ppclip|csv|npz|rec)["']"""
    )
    found = []
    for package in PACKAGES:
        for path in sorted((ROOT / package).rglob("*.py")):
            if path == ROOT / "engine" / "io" / "formats.py":
                continue
            found += [
                f"{path.relative_to(ROOT)}:{n}"
                for n, line in enumerate(path.read_text().splitlines(), 1)
                if listed.search(line)
            ]
    assert not found, found


def test_a_command_refuses_an_unknown_suffix_with_the_registry_list(tmp_path: Path) -> None:
    take = tmp_path / "take.txt"
    take.write_text("not a motion file")
    r = subprocess.run(
        [
            sys.executable,
            "-m",
            "puppetphone",
            "clips",
            "--clips",
            str(tmp_path / "lib"),
            "add",
            str(take),
            "--role",
            "walk",
        ],
        check=False,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 2 and ", ".join(SOURCE_SUFFIXES) in r.stderr
