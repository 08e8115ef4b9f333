"""What a user installs: the card's packages and the launcher, typed, and nothing generic.

The wheel is built from this checkout (as ``pip install .`` builds it) and its file list read:
a top-level ``bench`` or ``tools`` would collide with other distributions and ship developer
scripts to every user; ``py.typed`` tells type checkers the packages carry their annotations.
"""

from __future__ import annotations

import subprocess
import sys
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGES = {"engine", "input", "authoring", "games", "puppetphone"}


def test_the_wheel_installs_only_the_cards_packages_and_marks_them_typed(tmp_path: Path) -> None:
    subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(tmp_path), str(ROOT)],
        check=True,
        capture_output=True,
        timeout=600,
    )
    (wheel,) = tmp_path.glob("puppetphone-*.whl")
    names = zipfile.ZipFile(wheel).namelist()
    top = {n.split("/")[0] for n in names if not n.split("/")[0].endswith((".dist-info", ".data"))}
    assert top == PACKAGES
    assert {f"{p}/py.typed" for p in PACKAGES} <= set(names)
    assert "puppetphone/bench/crowd.py" in names  # the benches ship inside the launcher
    assert "input/web/page/index.html" in names  # and the data files still do
