"""The contour search imports ``cma`` without matplotlib: no font-cache build (~20 s the first time),
no stray line on stderr. Broken by ``import cma`` in ``abstract_contour`` (matplotlib gets imported)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

_PROBE = """
import sys
import numpy as np
from authoring.flowcurves.contours import abstract_contour
t = np.linspace(0, 2 * np.pi, 60, endpoint=False)
abstract_contour(np.c_[50 + 20 * np.cos(t), 50 + 30 * np.sin(t)], max_evaluations=200)
print("matplotlib" in sys.modules)
"""


def test_a_contour_search_imports_no_plotting_and_prints_nothing(tmp_path: Path) -> None:
    env = dict(os.environ, MPLCONFIGDIR=str(tmp_path / "mpl"), PYTHONWARNINGS="always")
    done = subprocess.run(
        [sys.executable, "-c", _PROBE],
        check=False,
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
        cwd=Path(__file__).resolve().parents[3],
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "False"
    assert done.stderr == ""
