"""Start-up: ``play snowman --headless --frames 1`` against importing the libraries it stands on.

A start is mostly imports (numpy, SciPy, MuJoCo, moderngl…) plus our own set-up; the issue asks
that our share be at most the libraries' own: ``startup_s_play_snowman`` ≤ 2 × the import of
those heavy libraries alone. Both run as fresh processes (``sys.executable``), timed in process
CPU time of the child (user + system, from ``os.wait4``: the machine is shared), median of
:data:`REPEATS`. The built-in lookup table is read from the user cache (a first run fills it and is
not counted).
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile

import numpy as np

from puppetphone.bench.figures import Figure

__all__ = ["run", "child_cpu_s", "HEAVY", "REPEATS"]

REPEATS = 3
# the third-party packages `play snowman` imports (SciPy by the subpackages it loads)
HEAVY = (
    "numpy",
    "scipy.spatial",
    "scipy.sparse",
    "scipy.linalg",
    "scipy.optimize",
    "scipy.interpolate",
    "scipy.ndimage",
    "scipy.fft",
    "scipy.special",
    "mujoco",
    "moderngl",
    "daqp",
    "pythonosc",
    "websockets",
)


def child_cpu_s(args: list[str]) -> float:
    """Process CPU seconds (user + system) of one child process running ``args``."""
    env = dict(os.environ, SDL_VIDEODRIVER="dummy")
    with tempfile.TemporaryFile() as err:
        proc = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=err, env=env)
        _, status, usage = os.wait4(proc.pid, 0)
        proc.returncode = os.waitstatus_to_exitcode(status)  # reaped here: tell Popen
        if proc.returncode != 0:
            err.seek(0)
            raise RuntimeError(f"{' '.join(args)} failed: {err.read().decode(errors='replace').strip()[-300:]}")
    return usage.ru_utime + usage.ru_stime


def run() -> list[Figure]:
    """``startup_s_play_snowman`` beside the heavy libraries' import, same run."""
    play = [sys.executable, "-m", "puppetphone", "play", "snowman", "--headless", "--frames", "1"]
    imports = [sys.executable, "-c", "import " + ", ".join(HEAVY)]
    child_cpu_s(play)  # fills the lookup cache and the OS file cache
    child_cpu_s(imports)
    starts = [child_cpu_s(play) for _ in range(REPEATS)]
    libs = [child_cpu_s(imports) for _ in range(REPEATS)]
    return [
        Figure(
            "startup",
            "startup_s_play_snowman",
            float(np.median(starts)),
            "s",
            "import of its heavy libraries",
            float(np.median(libs)),
        ),
    ]
