"""Conformance in CI (issue 24 item 8): the Khronos glTF validator on every kind of glTF the project writes,
and round trips BVH -> clip -> BVH/glTF -> clip that compare joint positions.

The validator is the npm package ``gltf-validator`` that ``.ci/run`` installs into
``${XDG_CACHE_HOME:-~/.cache}/puppetphone/npm`` (or ``$PUPPETPHONE_NPM``); driven by ``tools/gltf_validate.js``.
Without node or the package the validator test skips and says so.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from engine.clips import default_clips
from engine.fk import forward_kinematics
from engine.io.bvh import write_bvh
from engine.io.bvh_convert import clip_to_bvh
from engine.io.gltf_write import write_gltf
from engine.io.motion_file import load_motion
from tests.engine.io.synthetic_bvh import human_bvh

_ROOT = Path(__file__).resolve().parents[3]


def npm_dir() -> Path:
    """Where ``.ci/run`` installs the validator: ``${XDG_CACHE_HOME:-$HOME/.cache}/puppetphone/npm``."""
    if os.environ.get("PUPPETPHONE_NPM"):
        return Path(os.environ["PUPPETPHONE_NPM"])
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "puppetphone" / "npm"


def test_the_validator_is_looked_for_where_ci_installs_it(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    """Shown to fail with the old lookup (always ``~/.cache``): under CI's ``XDG_CACHE_HOME`` it skipped silently."""
    monkeypatch.delenv("PUPPETPHONE_NPM", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert npm_dir() == tmp_path / "puppetphone" / "npm"
    monkeypatch.setenv("XDG_CACHE_HOME", "")  # empty counts as unset, as in bash's ${XDG_CACHE_HOME:-...}
    assert npm_dir() == Path.home() / ".cache" / "puppetphone" / "npm"
    ci = (_ROOT / ".ci" / "run").read_text()
    assert 'gltf_npm="${XDG_CACHE_HOME:-$HOME/.cache}/puppetphone/npm"' in ci


def _validator() -> tuple[str, Path]:
    node = shutil.which("node")
    npm_dir_ = npm_dir()
    if node is None:
        pytest.skip("node is not installed (the Khronos glTF validator runs on node; .ci/run installs npm)")
    if not (npm_dir_ / "node_modules" / "gltf-validator").is_dir():
        pytest.skip(f"gltf-validator not found in {npm_dir_}/node_modules (.ci/run installs it with npm)")
    return node, npm_dir_ / "node_modules"


def _written_gltfs(out: Path) -> list[Path]:
    """One file of every kind the project writes: clips, channels, loops from `cycle`, MoCurves exports."""
    from authoring.mocurves.storage import export_clip

    files = []
    for name, clip in default_clips().items():
        files.append(write_gltf(out / f"{name}.glb", clip))
    walk = default_clips()["walk"]
    files.append(write_gltf(out / "walk.gltf", walk))
    files.append(export_clip(walk, out / "walk_mocurves.glb"))
    src = out / "stretch.bvh"
    src.write_text(human_bvh(stretch=0.08, frames=150))
    clip = load_motion(src).clip
    scales = 1.0 + 0.2 * np.sin(np.linspace(0, 2 * np.pi, clip.num_frames))[:, None] * (
        np.arange(clip.skeleton.num_joints) == 4
    )
    files.append(write_gltf(out / "channels.glb", replace(clip, scales=scales)))
    for suffix in (".glb", ".gltf"):
        r = subprocess.run(
            [sys.executable, "-m", "puppetphone", "cycle", str(src), "-o", f"loop{suffix}"],
            cwd=out,
            capture_output=True,
            text=True,
            timeout=300,
        )
        assert r.returncode == 0, r.stderr
        files.append(out / f"loop{suffix}")
    return files


def test_khronos_validator_reports_no_errors_or_warnings_on_our_gltf(tmp_path: Path) -> None:
    node, modules = _validator()
    files = _written_gltfs(tmp_path)
    r = subprocess.run(
        [node, str(_ROOT / "tools" / "gltf_validate.js"), *map(str, files)],
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "NODE_PATH": str(modules)},
    )
    reports = [json.loads(line) for line in r.stdout.splitlines() if line.startswith("{")]
    assert len(reports) == len(files), r.stderr
    bad = [rep for rep in reports if rep["errors"] or rep["warnings"]]
    assert not bad, bad
    assert r.returncode == 0


def _positions(clip):  # type: ignore[no-untyped-def]
    return forward_kinematics(clip.skeleton, clip.root, clip.rotations, clip.translations, clip.scales)[0]


@pytest.mark.parametrize("stretch", [0.0, 0.08])
def test_round_trip_bvh_clip_bvh_and_gltf_keeps_joint_positions(tmp_path: Path, stretch: float) -> None:
    src = tmp_path / "src.bvh"
    src.write_text(human_bvh(stretch=stretch, frames=90))
    clip = load_motion(src, skip_tpose=False).clip
    want = _positions(clip)
    write_bvh(tmp_path / "back.bvh", clip_to_bvh(clip))
    write_gltf(tmp_path / "back.glb", clip)
    write_gltf(tmp_path / "back.gltf", clip)
    for name in ("back.bvh", "back.glb", "back.gltf"):
        back = load_motion(tmp_path / name, skip_tpose=False).clip
        assert back.skeleton.names == clip.skeleton.names and back.num_frames == clip.num_frames
        assert np.abs(_positions(back) - want).max() < 1e-4, name  # 0.1 mm (glTF keeps float32)


def test_round_trip_of_real_mocap(mocap_dir: Path, tmp_path: Path) -> None:
    for name in ("cmu_16_15_walk_daz.bvh", "bandai1_walk_normal_001.bvh", "cmu_02_01_walk_ccbase.bvh"):
        clip = load_motion(mocap_dir / name).clip
        want = _positions(clip)
        write_bvh(tmp_path / name, clip_to_bvh(clip))
        write_gltf(tmp_path / (name + ".glb"), clip)
        for back_path in (tmp_path / name, tmp_path / (name + ".glb")):
            back = load_motion(back_path, skip_tpose=False).clip
            assert np.abs(_positions(back) - want).max() < 2e-4, back_path.name
