"""``author edit`` of a skinned GLB draws the file's own character, textured, in place of the
mannequin (issue 36 item 3) — live, and in a replay after the file is gone (the recording
carries it)."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
from PIL import Image

_ENV = {**os.environ, "SDL_VIDEODRIVER": "dummy", "SDL_AUDIODRIVER": "dummy"}


def _run(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "puppetphone", *args], cwd=cwd, env=_ENV, capture_output=True, text=True, timeout=300
    )


def _figure_colours(path: Path) -> int:
    """Distinct colours (in 16 steps a channel) in the centre of the picture, where the figure stands."""
    img = np.asarray(Image.open(path).convert("RGB"), dtype=np.int32)
    h, w = img.shape[:2]
    centre = img[h // 8 : 7 * h // 8, 3 * w // 8 : 5 * w // 8].reshape(-1, 3)
    return len(np.unique(centre // 16, axis=0))


def test_the_character_of_a_glb_is_drawn_and_replays_without_its_file(mocap_dir: Path, tmp_path: Path) -> None:
    shutil.copy(mocap_dir / "CesiumMan.glb", tmp_path / "cesium.glb")
    r = _run(
        "author",
        "edit",
        "cesium.glb",
        "--headless",
        "--frames",
        "30",
        "--screenshot",
        "live.png",
        "--record",
        "edit.rec",
        cwd=tmp_path,
    )
    assert r.returncode == 0, r.stderr
    live = _figure_colours(tmp_path / "live.png")
    # The same loop as a BVH has no skin: the mannequin's grey capsules, few colours.
    r = _run(
        "author",
        "edit",
        str(mocap_dir / "cmu_16_15_walk_daz.bvh"),
        "--headless",
        "--frames",
        "30",
        "--screenshot",
        "mannequin.png",
        cwd=tmp_path,
    )
    assert r.returncode == 0, r.stderr
    assert live > 3 * _figure_colours(tmp_path / "mannequin.png")  # CesiumMan's painted texture
    (tmp_path / "cesium.glb").unlink()
    again = _run("replay", "edit.rec", "--verify", "--headless", "--screenshot", "replayed.png", cwd=tmp_path)
    assert again.returncode == 0, again.stdout + again.stderr
    assert _figure_colours(tmp_path / "replayed.png") > 0.8 * live
